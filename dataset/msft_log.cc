#include "dataset/msft_log.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "common/circular.h"

namespace ratslam::dataset {
namespace {

constexpr double kMaxTimeMs = 1e15;    // epoch milliseconds (year 2001 is 1e12)
constexpr double kMaxSensor = 1e4;     // accelerations (m/s^2) and rotation-vector parts
constexpr double kMaxPositionM = 1e7;  // waypoint coordinates in a building's frame

std::vector<std::string> SplitTabs(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, '\t')) {
    if (!field.empty() && field.back() == '\r') field.pop_back();
    fields.push_back(field);
  }
  return fields;
}

bool ParseNumber(const std::string& text, double* value) {
  if (text.empty()) return false;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), *value);
  return result.ec == std::errc() && result.ptr == text.data() + text.size() &&
         std::isfinite(*value);
}

}  // namespace

std::optional<int> FloorFromName(const std::string& name) {
  if (name.size() < 2 || (name[0] != 'B' && name[0] != 'F')) return std::nullopt;
  int n = 0;
  const auto result = std::from_chars(name.data() + 1, name.data() + name.size(), n);
  // Floors are within +-1000 like every floor the replay format stores (found by the fuzzer:
  // "B9496900" became a floor the written data set could not read back).
  if (result.ec != std::errc() || result.ptr != name.data() + name.size() || n < 1 || n > 1000) {
    return std::nullopt;
  }
  return name[0] == 'B' ? -n : n - 1;
}

double HeadingFromRotationVector(double x, double y, double z) {
  const double w = std::sqrt(std::max(0.0, 1.0 - x * x - y * y - z * z));
  // Device y axis in the world frame: the second column of the rotation matrix.
  const double east = 2.0 * (x * y - z * w);
  const double north = 1.0 - 2.0 * (x * x + z * z);
  return std::atan2(north, east);
}

StatusOr<PhoneLog> ParseMicrosoftLog(const std::string& path, const PhoneLogOptions& options,
                                     PhoneLogReport* report, double max_wifi_staleness_s) {
  std::ifstream in;
  RATSLAM_RETURN_IF_ERROR(OpenPhoneLog(path, &in));
  PhoneLogReport local_report;
  PhoneLogReport& r = report ? *report : local_report;
  r = PhoneLogReport();

  PhoneLogStreams streams;
  std::vector<sensors::AccelerometerSample>& accelerometer = streams.accelerometer;
  std::vector<sensors::HeadingSample>& headings = streams.headings;
  std::map<double, std::vector<WifiReading>>& scans = streams.scans;
  std::vector<GroundTruthRow>& waypoints = streams.ground_truth;
  int floor = 0;
  double start_ms = std::numeric_limits<double>::quiet_NaN();
  std::string line;
  int number = 0;
  for (bool more = true;;) {
    RATSLAM_RETURN_IF_ERROR(ReadPhoneLogLine(in, path, number, &line, &more));
    if (!more) break;
    ++number;
    ++r.lines;
    if (line.empty() || line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::vector<std::string> f = SplitTabs(line);
    if (line[0] == '#') {
      for (const std::string& field : f) {
        if (field.rfind("FloorName:", 0) == 0) {
          if (auto n = FloorFromName(field.substr(10))) floor = *n;
        }
        double start = 0.0;
        if (field.rfind("startTime:", 0) == 0 && ParseNumber(field.substr(10), &start) &&
            start >= 0 && start <= kMaxTimeMs && std::isnan(start_ms)) {
          start_ms = start;  // times count from the recording's start
        }
      }
      continue;
    }
    const std::string type = f.size() > 1 ? f[1] : "";
    auto fail = [&](const std::string& what) {
      return Status::Error(path + ":" + std::to_string(number) + ": " +
                           (type.empty() ? std::string("line") : type) + ": " + what);
    };
    std::vector<double> v(f.size(), 0.0);
    // Every number is range-checked (`limit` on its magnitude): corrupt values must not become
    // infinite times or positions.
    auto numbers = [&](std::initializer_list<size_t> indices, double limit) {
      for (size_t i : indices) {
        if (i >= f.size()) return fail("missing field " + std::to_string(i + 1));
        if (!ParseNumber(f[i], &v[i])) {
          return fail("field " + std::to_string(i + 1) + " is not a number: '" + f[i] + "'");
        }
        if (!(std::abs(v[i]) <= limit)) {
          return fail("field " + std::to_string(i + 1) + " is out of range: '" + f[i] + "'");
        }
      }
      return Status::Ok();
    };
    Status status = numbers({0}, kMaxTimeMs);
    if (status.ok() && v[0] < 0) status = fail("negative timestamp");
    if (status.ok() && std::isnan(start_ms)) start_ms = v[0];
    if (status.ok() && v[0] < start_ms) {
      status = fail("timestamp " + f[0] + " is before the walk's start time");
    }
    const double t = status.ok() ? (v[0] - start_ms) / 1000.0 : 0.0;
    if (!status.ok()) {
      // the timestamp itself is broken
    } else if (type == "TYPE_WIFI") {
      status = f.size() < 6 ? fail("expected ssid, bssid, rssi, frequency and last-seen time")
                            : numbers({5, 6 < f.size() ? size_t{6} : size_t{5}}, kMaxTimeMs);
      if (status.ok()) status = numbers({4}, 200.0);
      if (status.ok() && f[3].empty()) status = fail("empty BSSID");
      if (status.ok()) {
        const bool stale = f.size() > 6 && v[0] - v[6] > max_wifi_staleness_s * 1000.0;
        if (!stale) scans[t].push_back({f[3], v[4]});
      }
    } else if (type == "TYPE_ACCELEROMETER") {
      status = numbers({2, 3, 4}, kMaxSensor);
      if (status.ok()) accelerometer.push_back({t, v[2], v[3], v[4]});
    } else if (type == "TYPE_ROTATION_VECTOR") {
      status = numbers({2, 3, 4}, kMaxSensor);
      if (status.ok()) headings.push_back({t, HeadingFromRotationVector(v[2], v[3], v[4])});
    } else if (type == "TYPE_WAYPOINT") {
      status = numbers({2, 3}, kMaxPositionM);
      if (status.ok()) {
        GroundTruthRow row;
        row.time_s = t;
        row.x_m = v[2];
        row.y_m = v[3];
        row.floor = floor;
        waypoints.push_back(row);
      }
    } else {
      ++r.skipped_other_types;
      continue;
    }
    if (!status.ok()) {
      if (!options.lenient) return status;
      ++r.skipped_malformed;
    }
  }
  if (in.bad()) return Status::Error(path + ": read error");
  if (std::isnan(start_ms)) return Status::Error(path + ": no data lines (not a Microsoft walk?)");
  for (GroundTruthRow& w : waypoints) w.floor = floor;  // FloorName may follow the first lines
  return PhoneLog{std::filesystem::path(path).stem().string(), 0.0, std::move(streams)};
}

}  // namespace ratslam::dataset
