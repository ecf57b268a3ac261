#include "dataset/ipin_log.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>

#include "common/circular.h"
#include "common/text_file.h"

namespace ratslam::dataset {
namespace {

constexpr double kEarthRadiusM = 6371008.8;  // mean Earth radius (IUGG)
constexpr double kMaxTimeS = 1e12;           // app timestamps: seconds, never negative
constexpr double kMaxSensor = 1e4;  // accelerations (m/s^2) and angles (deg) beyond are corrupt

struct Field {
  size_t index;
  const char* name;
  double min, max;
};

std::string FormatBound(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", v);
  return buffer;
}

std::vector<std::string> Split(const std::string& line) {
  std::vector<std::string> fields;
  size_t start = 0;
  while (true) {
    const size_t end = line.find(';', start);
    fields.push_back(
        line.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  // A trailing ';' (some logs end WIFI lines with one) leaves an empty last field.
  if (fields.size() > 1 && fields.back().find_first_not_of(" \t\r") == std::string::npos) {
    fields.pop_back();
  }
  return fields;
}

bool ParseDouble(const std::string& text, double* value) {
  // Blank (spaces, tabs, a carriage return) is no number; the end is found before any pointer
  // is formed (text.data() + npos would overflow).
  const auto begin = text.find_first_not_of(" \t\r");
  const auto end = text.find_last_not_of(" \t\r");
  if (begin == std::string::npos || end == std::string::npos) return false;
  const char* first = text.data() + begin;
  const char* last = text.data() + (end + 1);
  const auto result = std::from_chars(first, last, *value);
  return result.ec == std::errc() && result.ptr == last && std::isfinite(*value);
}

// A sensor type as the logs write it: 2 to 8 capital letters or digits, starting with a letter
// (WIFI, ACCE, BLE4, ...).
bool IsSensorType(const std::string& type) {
  if (type.size() < 2 || type.size() > 8 || !(type[0] >= 'A' && type[0] <= 'Z')) return false;
  for (char c : type) {
    if (!((c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9'))) return false;
  }
  return true;
}

// `text` quoted, with every byte that is not printable ASCII written as \xNN.
std::string Printable(const std::string& text) {
  std::string out = "'";
  for (unsigned char c : text) {
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      char hex[5];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
    }
  }
  return out + "'";
}

}  // namespace

void GeoToLocal(const GeoReference& reference, double latitude_deg, double longitude_deg,
                double* x_m, double* y_m) {
  const double to_rad = std::numbers::pi / 180.0;
  *x_m = kEarthRadiusM * std::cos(reference.latitude_deg * to_rad) *
         (longitude_deg - reference.longitude_deg) * to_rad;
  *y_m = kEarthRadiusM * (latitude_deg - reference.latitude_deg) * to_rad;
}

StatusOr<PhoneLog> ParseIpinLog(const std::string& path, const PhoneLogOptions& options,
                                PhoneLogReport* report) {
  std::ifstream in;
  RATSLAM_RETURN_IF_ERROR(OpenPhoneLog(path, &in));
  PhoneLogReport local_report;
  PhoneLogReport& r = report ? *report : local_report;
  r = PhoneLogReport();

  PhoneLogStreams streams;
  std::vector<sensors::AccelerometerSample>& accelerometer = streams.accelerometer;
  std::vector<sensors::HeadingSample>& headings = streams.headings;
  std::map<double, std::vector<WifiReading>>& scans = streams.scans;  // by app timestamp
  struct Posi {
    double time_s, latitude, longitude;
    int floor;
  };
  std::vector<Posi> posi;
  std::string line;
  int number = 0;
  double first_time = std::numeric_limits<double>::infinity();
  for (bool more = true;;) {
    RATSLAM_RETURN_IF_ERROR(ReadPhoneLogLine(in, path, number, &line, &more));
    if (!more) break;
    ++number;
    ++r.lines;
    if (line.empty() || line[0] == '%' || line.find_first_not_of(" \t\r") == std::string::npos) {
      continue;
    }
    const std::vector<std::string> f = Split(line);
    const std::string& type = f[0];
    auto fail = [&](const std::string& what) -> Status {
      return Status::Error(path + ":" + std::to_string(number) + ": " + type + ": " + what);
    };
    // Unknown sensor types are skipped, but a line must have the shape of a sensor line
    // (TYPE;..., TYPE four capitals or digits as in every log of the competition): random bytes,
    // a run of NULs or a line cut before its first ';' are errors, not "other sensors".
    if (!IsSensorType(type) || f.size() < 2) {
      const Status status = Status::Error(path + ":" + std::to_string(number) +
                                          ": not a sensor line of the form TYPE;... (it starts " +
                                          Printable(line.substr(0, 24)) + ")");
      if (!options.lenient) return status;
      ++r.skipped_malformed;
      continue;
    }
    std::vector<double> v(f.size(), 0.0);
    // Every number is range-checked: a latitude of 4000 degrees or a floor of 1e300 is a
    // corrupt line, not a position 440,000 km away or floor 0.
    auto numbers = [&](std::initializer_list<Field> fields) {
      for (const Field& field : fields) {
        if (field.index >= f.size()) return fail(std::string("missing field ") + field.name);
        if (!ParseDouble(f[field.index], &v[field.index])) {
          return fail(std::string(field.name) + " is not a number: '" + f[field.index] + "'");
        }
        if (!(v[field.index] >= field.min && v[field.index] <= field.max)) {
          return fail(std::string(field.name) + " is out of range [" + FormatBound(field.min) +
                      ", " + FormatBound(field.max) + "]: '" + f[field.index] + "'");
        }
      }
      return Status::Ok();
    };
    Status status;
    if (type == "WIFI") {
      // WIFI;App;Sensor;SSID;BSSID;[Frequency;]RSS
      if (f.size() != 6 && f.size() != 7) {
        status = fail("expected 6 or 7 fields, found " + std::to_string(f.size()));
      } else {
        const size_t rss = f.size() - 1;
        status = numbers({{1, "AppTimestamp(s)", 0, kMaxTimeS}, {rss, "RSS(dBm)", -200, 50}});
        if (status.ok() && f[4].empty()) status = fail("empty BSSID");
        if (status.ok()) scans[v[1]].push_back({f[4], v[rss]});
      }
    } else if (type == "ACCE") {
      status = numbers({{1, "AppTimestamp(s)", 0, kMaxTimeS},
                        {3, "Acc_X", -kMaxSensor, kMaxSensor},
                        {4, "Acc_Y", -kMaxSensor, kMaxSensor},
                        {5, "Acc_Z", -kMaxSensor, kMaxSensor}});
      if (status.ok()) accelerometer.push_back({v[1], v[3], v[4], v[5]});
    } else if (type == "AHRS") {
      status = numbers(
          {{1, "AppTimestamp(s)", 0, kMaxTimeS}, {5, "YawZ(deg)", -kMaxSensor, kMaxSensor}});
      // The app's yaw turns counter-clockwise from north (checked on the training logs: dead
      // reckoning with it needs 2-10 degrees of rotation to fit the ground truth, and the
      // clockwise reading fits 2-3 times worse). Ours: counter-clockwise from east.
      if (status.ok()) {
        headings.push_back({v[1], WrapAngle(v[5] * std::numbers::pi / 180 + std::numbers::pi / 2)});
      }
    } else if (type == "PRES") {
      // PRES;AppTimestamp;SensorTimestamp;Pressure(mbar);Accuracy
      status = numbers({{1, "AppTimestamp(s)", 0, kMaxTimeS}, {3, "Pressure(mbar)", 100, 1100}});
      if (status.ok()) streams.pressure.push_back({v[1], v[3]});
    } else if (type == "POSI") {
      status = numbers({{1, "Timestamp(s)", 0, kMaxTimeS},
                        {3, "Latitude", -90, 90},
                        {4, "Longitude", -180, 180},
                        {5, "floor", -1000, 1000}});
      if (status.ok() && v[5] != std::floor(v[5])) status = fail("floor is not a whole number");
      if (status.ok()) posi.push_back({v[1], v[3], v[4], static_cast<int>(v[5])});
    } else {
      ++r.skipped_other_types;
      continue;
    }
    if (!status.ok()) {
      if (!options.lenient) return status;
      ++r.skipped_malformed;
      continue;
    }
    first_time = std::min(first_time, v[1]);
  }
  if (in.bad()) return Status::Error(path + ": read error");
  if (!std::isfinite(first_time))
    return Status::Error(path + ": no sensor lines (not an IPIN log?)");

  std::stable_sort(posi.begin(), posi.end(),
                   [](const Posi& a, const Posi& b) { return a.time_s < b.time_s; });
  std::stable_sort(
      streams.pressure.begin(), streams.pressure.end(),
      [](const PressureSample& a, const PressureSample& b) { return a.time_s < b.time_s; });
  if (!posi.empty()) {
    r.reference = options.reference ? *options.reference
                                    : GeoReference{posi.front().latitude, posi.front().longitude};
    for (const Posi& p : posi) {
      GroundTruthRow row;
      row.time_s = p.time_s;
      GeoToLocal(r.reference, p.latitude, p.longitude, &row.x_m, &row.y_m);
      row.floor = p.floor;
      streams.ground_truth.push_back(row);
    }
  }
  return PhoneLog{std::filesystem::path(path).stem().string(), first_time, std::move(streams)};
}

}  // namespace ratslam::dataset
