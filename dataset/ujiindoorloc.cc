#include "dataset/ujiindoorloc.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "common/text_file.h"

namespace ratslam::dataset {
namespace {

constexpr double kNotDetected = 100.0;
// Largest magnitude of each label column, in the order of `labels` below: metres (UTM), ids,
// seconds. Ids are whole numbers that fit an int; larger values are corrupt rows.
constexpr double kLabelLimits[] = {1e8, 1e8, 1e6, 1e6, 1e6, 1e6, 1e6, 1e6, 1e12};

std::vector<std::string> SplitCommas(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) {
    if (!field.empty() && field.back() == '\r') field.pop_back();
    fields.push_back(field);
  }
  if (!line.empty() && line.back() == ',') fields.push_back("");
  return fields;
}

bool ParseNumber(const std::string& text, double* value) {
  if (text.empty()) return false;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), *value);
  return r.ec == std::errc() && r.ptr == text.data() + text.size() && std::isfinite(*value);
}

}  // namespace

StatusOr<std::vector<LabelledScan>> ReadUjiIndoorLoc(const std::string& path, bool lenient,
                                                     UjiReadReport* report) {
  std::ifstream in;
  RATSLAM_RETURN_IF_ERROR(OpenRegularFile(path, "file", &in));
  UjiReadReport local;
  UjiReadReport& r = report ? *report : local;
  r = UjiReadReport();
  std::string line;
  // The real file has 529 columns: its lines are about 2 kB.
  if (ReadLine(in, &line) != LineResult::kLine) return Status::Error(path + ": empty file");
  const std::vector<std::string> header = SplitCommas(line);
  std::vector<size_t> waps;
  const char* labels[] = {"LONGITUDE",        "LATITUDE", "FLOOR",   "BUILDINGID", "SPACEID",
                          "RELATIVEPOSITION", "USERID",   "PHONEID", "TIMESTAMP"};
  std::vector<int> label_column(std::size(labels), -1);
  for (size_t i = 0; i < header.size(); ++i) {
    if (header[i].rfind("WAP", 0) == 0) {
      waps.push_back(i);
      continue;
    }
    bool known = false;
    for (size_t k = 0; k < std::size(labels); ++k) {
      if (header[i] == labels[k]) {
        label_column[k] = static_cast<int>(i);
        known = true;
      }
    }
    if (!known) return Status::Error(path + ":1: unknown column '" + header[i] + "'");
  }
  for (size_t k = 0; k < 4; ++k) {
    if (label_column[k] < 0) {
      return Status::Error(path + ":1: missing required column '" + std::string(labels[k]) + "'");
    }
  }
  if (waps.empty()) return Status::Error(path + ":1: no WAP columns");
  r.access_points = waps.size();
  std::vector<LabelledScan> scans;
  int number = 1;
  for (;;) {
    const LineResult read = ReadLine(in, &line);
    if (read == LineResult::kEnd) break;
    ++number;
    if (read == LineResult::kTooLong) {
      return Status::Error(path + ":" + std::to_string(number) + ": line longer than " +
                           std::to_string(kMaxLineBytes) + " bytes");
    }
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    ++r.rows;
    const std::vector<std::string> f = SplitCommas(line);
    auto error = [&](const std::string& column, const std::string& what) {
      return Status::Error(path + ":" + std::to_string(number) + ": column '" + column +
                           "': " + what);
    };
    Status status;
    LabelledScan s;
    s.line = number;
    if (f.size() != header.size()) {
      status = Status::Error(path + ":" + std::to_string(number) + ": expected " +
                             std::to_string(header.size()) + " fields, found " +
                             std::to_string(f.size()) + " (truncated or malformed row)");
    }
    for (size_t i = 0; status.ok() && i < waps.size(); ++i) {
      double v = 0;
      if (!ParseNumber(f[waps[i]], &v)) {
        status = error(header[waps[i]], "not a number: '" + f[waps[i]] + "'");
      } else if (v != kNotDetected) {
        if (v > 0 || v < -120) status = error(header[waps[i]], "RSSI out of range: " + f[waps[i]]);
        s.readings.push_back({header[waps[i]], v});
      }
    }
    double values[std::size(labels)] = {};
    for (size_t k = 0; status.ok() && k < std::size(labels); ++k) {
      if (label_column[k] < 0) continue;
      if (!ParseNumber(f[label_column[k]], &values[k])) {
        status = error(labels[k], "not a number: '" + f[label_column[k]] + "'");
      } else if (!(std::abs(values[k]) <= kLabelLimits[k])) {
        status = error(labels[k], "out of range: '" + f[label_column[k]] + "'");
      } else if (k >= 2 && k < 8 && values[k] != std::floor(values[k])) {
        status = error(labels[k], "not a whole number: '" + f[label_column[k]] + "'");
      } else if (k == 8 && values[k] < 0) {
        status = error(labels[k], "negative time: '" + f[label_column[k]] + "'");
      }
    }
    if (!status.ok()) {
      if (!lenient) return status;
      ++r.skipped_malformed;
      continue;
    }
    s.x_m = values[0];
    s.y_m = values[1];
    s.floor = static_cast<int>(values[2]);
    s.building = static_cast<int>(values[3]);
    s.space = static_cast<int>(values[4]);
    s.user = static_cast<int>(values[6]);
    s.phone = static_cast<int>(values[7]);
    s.time_s = values[8];
    scans.push_back(std::move(s));
  }
  if (in.bad()) return Status::Error(path + ": read error");
  return scans;
}

}  // namespace ratslam::dataset
