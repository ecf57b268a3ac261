#include "dataset/phone_log.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/circular.h"
#include "common/text_file.h"
#include "dataset/ipin_log.h"
#include "dataset/msft_log.h"

namespace ratslam::dataset {
namespace {

Status CheckOptions(const PhoneLogOptions& options) {
  std::string error;
  if (!options.pdr.IsValid(&error)) return Status::Error("pdr." + error);
  if (!(options.compass_rate_hz > 0.0) || !std::isfinite(options.compass_rate_hz)) {
    return Status::Error("compass_rate_hz: must be positive");
  }
  return Status::Ok();
}

}  // namespace

Status OpenPhoneLog(const std::string& path, std::ifstream* in) {
  return OpenRegularFile(path, "log file", in);
}

Status ReadPhoneLogLine(std::istream& in, const std::string& path, int number, std::string* line,
                        bool* more) {
  const LineResult result = ReadLine(in, line);
  *more = result != LineResult::kEnd;
  if (result == LineResult::kTooLong) {
    return Status::Error(path + ":" + std::to_string(number + 1) + ": line longer than " +
                         std::to_string(kMaxLineBytes) + " bytes");
  }
  return Status::Ok();
}

StatusOr<Dataset> PhoneLogToDataset(PhoneLog log, const PhoneLogOptions& options,
                                    PhoneLogReport* report) {
  RATSLAM_RETURN_IF_ERROR(CheckOptions(options));
  PhoneLogStreams& streams = log.streams;
  auto by_time = [](const auto& a, const auto& b) { return a.time_s < b.time_s; };
  std::stable_sort(streams.accelerometer.begin(), streams.accelerometer.end(), by_time);
  std::stable_sort(streams.headings.begin(), streams.headings.end(), by_time);
  std::stable_sort(streams.ground_truth.begin(), streams.ground_truth.end(), by_time);
  std::stable_sort(streams.pressure.begin(), streams.pressure.end(), by_time);
  Dataset d;
  d.name = log.name;
  sensors::PdrReport pdr;
  const std::vector<sensors::Step> steps =
      sensors::PedestrianDeadReckoning(streams.accelerometer, streams.headings, options.pdr, &pdr);
  if (report) {
    report->steps = steps.size();
    report->steps_not_walking = pdr.steps_not_walking;
  }
  d.odometry = StepsToOdometry(steps, log.start_time_s);
  for (auto& [time, readings] : streams.scans) d.wifi.push_back({time, std::move(readings)});
  double last_compass = -std::numeric_limits<double>::infinity();
  for (const sensors::HeadingSample& h : streams.headings) {
    if (h.time_s - last_compass >= 1.0 / options.compass_rate_hz) {
      d.compass.push_back({h.time_s, h.heading_rad});
      last_compass = h.time_s;
    }
  }
  d.pressure = std::move(streams.pressure);
  d.ground_truth = std::move(streams.ground_truth);
  // Heading of the ground truth: the direction of travel towards the next point (the last point
  // keeps the direction from its predecessor).
  for (size_t i = 0; i < d.ground_truth.size(); ++i) {
    const size_t from = i + 1 < d.ground_truth.size() ? i : (i > 0 ? i - 1 : i);
    const size_t to = i + 1 < d.ground_truth.size() ? i + 1 : i;
    d.ground_truth[i].theta_rad = std::atan2(d.ground_truth[to].y_m - d.ground_truth[from].y_m,
                                             d.ground_truth[to].x_m - d.ground_truth[from].x_m);
  }
  return d;
}

std::vector<OdometryRow> StepsToOdometry(const std::vector<sensors::Step>& steps,
                                         double start_time_s) {
  std::vector<OdometryRow> rows;
  rows.push_back({start_time_s, 0.0, 0.0});
  double previous_time = start_time_s;
  double previous_heading = steps.empty() ? 0.0 : steps.front().heading_rad;
  for (const sensors::Step& s : steps) {
    const double dt = s.time_s - previous_time;
    if (dt <= 0.0) continue;  // a step at the start time carries no usable interval
    rows.push_back({s.time_s, s.length_m / dt, WrapAngle(s.heading_rad - previous_heading) / dt});
    previous_time = s.time_s;
    previous_heading = s.heading_rad;
  }
  return rows;
}

// The two-step readers: options are checked before the file is read, so a bad [pdr] section
// fails at once instead of after parsing a long log.
StatusOr<Dataset> ReadIpinLog(const std::string& path, const PhoneLogOptions& options,
                              PhoneLogReport* report) {
  RATSLAM_RETURN_IF_ERROR(CheckOptions(options));
  StatusOr<PhoneLog> log = ParseIpinLog(path, options, report);
  if (!log.ok()) return log.status();
  return PhoneLogToDataset(std::move(*log), options, report);
}

StatusOr<Dataset> ReadMicrosoftLog(const std::string& path, const PhoneLogOptions& options,
                                   PhoneLogReport* report, double max_wifi_staleness_s) {
  RATSLAM_RETURN_IF_ERROR(CheckOptions(options));
  StatusOr<PhoneLog> log = ParseMicrosoftLog(path, options, report, max_wifi_staleness_s);
  if (!log.ok()) return log.status();
  return PhoneLogToDataset(std::move(*log), options, report);
}

}  // namespace ratslam::dataset
