#include "dataset/uji_long_term.h"

#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>

#include "common/text_file.h"

namespace ratslam::dataset {
namespace {

namespace fs = std::filesystem;

constexpr double kNotDetected = 100.0;
constexpr double kMaxCoordinateM = 1e8;
constexpr double kMaxFloor = 1000.0;
constexpr double kMaxId = 2e9;
// MATLAB date numbers count days from the year 0; 719529 is 1970-01-01. The range read as date
// numbers is the years 1970 to 2100 (times before the Unix epoch are refused in every form).
constexpr double kDatenumUnixEpoch = 719529.0;
constexpr double kDatenumMin = 719529.0, kDatenumMax = 767011.0;
constexpr double kMaxSeconds = 1e12;
constexpr const char* kSuffixes[] = {"rss.csv", "crd.csv", "tms.csv", "ids.csv"};

struct Rows {
  std::string path;
  std::vector<std::vector<std::string>> fields;
  std::vector<int> lines;
};

std::string Trim(std::string_view s) {
  const size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return "";
  const size_t e = s.find_last_not_of(" \t\r");
  return std::string(s.substr(b, e - b + 1));
}

std::vector<std::string> Split(const std::string& line) {
  std::vector<std::string> fields;
  size_t start = 0;
  for (;;) {
    const size_t comma = line.find(',', start);
    fields.push_back(Trim(std::string_view(line).substr(
        start, comma == std::string::npos ? std::string::npos : comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return fields;
}

// Every non-blank line of a header-less CSV file.
Status ReadRows(const std::string& path, const std::string& what, Rows* rows) {
  std::ifstream in;
  RATSLAM_RETURN_IF_ERROR(OpenRegularFile(path, what, &in));
  rows->path = path;
  std::string line;
  for (int number = 1;; ++number) {
    const LineResult read = ReadLine(in, &line);
    if (read == LineResult::kEnd) break;
    if (read == LineResult::kTooLong) {
      return Status::Error(path + ":" + std::to_string(number) + ": line longer than " +
                           std::to_string(kMaxLineBytes) + " bytes");
    }
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    rows->fields.push_back(Split(line));
    rows->lines.push_back(number);
  }
  if (in.bad()) return Status::Error(path + ": read error");
  return Status::Ok();
}

bool ParseNumber(const std::string& text, double* value) {
  if (text.empty()) return false;
  const char* begin = text.data();
  if (*begin == '+') ++begin;  // from_chars does not take a leading '+'
  const auto r = std::from_chars(begin, text.data() + text.size(), *value);
  return r.ec == std::errc() && r.ptr == text.data() + text.size() && std::isfinite(*value);
}

std::string FieldName(const std::string& kind, size_t index) {
  if (kind == "rss") {
    char name[16];
    std::snprintf(name, sizeof name, "AP%03zu", index + 1);
    return name;
  }
  if (kind == "crd") return index == 0 ? "x" : index == 1 ? "y" : "floor";
  if (kind == "tms") return "time";
  return "id";
}

Status FieldError(const Rows& rows, size_t row, const std::string& field, const std::string& what) {
  return Status::Error(rows.path + ":" + std::to_string(rows.lines[row]) + ": field '" + field +
                       "': " + what);
}

Status RowError(const Rows& rows, size_t row, const std::string& what) {
  return Status::Error(rows.path + ":" + std::to_string(rows.lines[row]) + ": " + what);
}

std::optional<double> SecondsOfCivil(double year, double month, double day, double hour,
                                     double minute, double second) {
  using namespace std::chrono;
  for (double v : {year, month, day, hour, minute}) {
    if (v != std::floor(v)) return std::nullopt;
  }
  if (!(year >= 1970 && year <= 2100) || !(hour >= 0 && hour < 24) ||
      !(minute >= 0 && minute < 60) || !(second >= 0 && second < 61)) {
    return std::nullopt;
  }
  if (!(month >= 1 && month <= 12) || !(day >= 1 && day <= 31)) return std::nullopt;
  const year_month_day date{std::chrono::year(static_cast<int>(year)),
                            std::chrono::month(static_cast<unsigned>(month)),
                            std::chrono::day(static_cast<unsigned>(day))};
  if (!date.ok()) return std::nullopt;
  const double days = static_cast<double>(sys_days(date).time_since_epoch().count());
  return days * 86400.0 + hour * 3600.0 + minute * 60.0 + second;
}

// "YYYY-MM-DD HH:MM:SS[.fff]" or with 'T' between date and time.
std::optional<double> SecondsOfText(const std::string& text) {
  if (text.size() < 19 || text[4] != '-' || text[7] != '-' ||
      (text[10] != ' ' && text[10] != 'T') || text[13] != ':' || text[16] != ':') {
    return std::nullopt;
  }
  double parts[6];
  const size_t starts[6] = {0, 5, 8, 11, 14, 17};
  const size_t lengths[6] = {4, 2, 2, 2, 2, std::string::npos};
  for (int k = 0; k < 6; ++k) {
    const std::string part = text.substr(starts[k], lengths[k]);
    if (part.empty() || part[0] < '0' || part[0] > '9' || !ParseNumber(part, &parts[k])) {
      return std::nullopt;
    }
  }
  return SecondsOfCivil(parts[0], parts[1], parts[2], parts[3], parts[4], parts[5]);
}

// The published files' form: yyyymmddHHMMSSfff (17 digits, milliseconds last) or yyyymmddHHMMSS
// (14), e.g. 20160602155217232. Nothing when the text is not 14 or 17 digits.
std::optional<double> SecondsOfDigits(const std::string& text) {
  if ((text.size() != 17 && text.size() != 14) ||
      !std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return std::nullopt;
  }
  auto part = [&](size_t at, size_t length) {
    double v = 0;
    for (size_t i = at; i < at + length; ++i) v = v * 10 + (text[i] - '0');
    return v;
  };
  const double milliseconds = text.size() == 17 ? part(14, 3) : 0.0;
  const auto civil =
      SecondsOfCivil(part(0, 4), part(4, 2), part(6, 2), part(8, 2), part(10, 2), part(12, 2));
  if (!civil) return std::nullopt;
  return *civil + milliseconds / 1000.0;
}

// The row's time in seconds, or an error.
Status ParseTime(const Rows& rows, size_t row, double* seconds) {
  const std::vector<std::string>& f = rows.fields[row];
  if (f.size() == 1) {
    if (f[0].size() == 17 || f[0].size() == 14) {
      // Digits only: the published timestamp form (a number of seconds has at most 13 digits
      // before 2100, so 14 and 17 digits are never seconds).
      if (const auto s = SecondsOfDigits(f[0])) {
        *seconds = *s;
        return Status::Ok();
      }
      if (std::all_of(f[0].begin(), f[0].end(), [](char c) { return c >= '0' && c <= '9'; })) {
        return FieldError(
            rows, row, "time",
            "'" + f[0] + "' is not a date yyyymmddHHMMSS" + (f[0].size() == 17 ? "fff" : ""));
      }
    }
    double v = 0;
    if (ParseNumber(f[0], &v)) {
      if (v >= kDatenumMin && v <= kDatenumMax) {
        *seconds = (v - kDatenumUnixEpoch) * 86400.0;
        return Status::Ok();
      }
      if (v < 0 || v > kMaxSeconds) return FieldError(rows, row, "time", "out of range: " + f[0]);
      *seconds = v;
      return Status::Ok();
    }
    if (auto s = SecondsOfText(f[0])) {
      *seconds = *s;
      return Status::Ok();
    }
    return FieldError(rows, row, "time",
                      "neither a number nor a date 'YYYY-MM-DD HH:MM:SS': '" + f[0] + "'");
  }
  if (f.size() == 6) {
    double v[6];
    for (int k = 0; k < 6; ++k) {
      if (!ParseNumber(f[k], &v[k])) {
        return FieldError(rows, row, "time",
                          "field " + std::to_string(k + 1) + " not a number: '" + f[k] + "'");
      }
    }
    if (auto s = SecondsOfCivil(v[0], v[1], v[2], v[3], v[4], v[5])) {
      *seconds = *s;
      return Status::Ok();
    }
    return FieldError(rows, row, "time", "not a date (year, month, day, hour, minute, second)");
  }
  return RowError(
      rows, row,
      "expected 1 field (a time) or 6 (year, month, day, hour, minute, second), found " +
          std::to_string(f.size()));
}

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

StatusOr<UjiLongTermFiles> FindUjiLongTermFiles(const std::string& path) {
  std::string stem;
  for (const char* suffix : kSuffixes) {
    if (EndsWith(path, suffix)) stem = path.substr(0, path.size() - std::string(suffix).size());
  }
  if (stem.empty() && !EndsWith(path, "rss.csv")) {
    return Status::Error(path + ": not a long-term UJI set file (<set>rss.csv, crd, tms or ids)");
  }
  UjiLongTermFiles files;
  files.rss = stem + kSuffixes[0];
  files.crd = stem + kSuffixes[1];
  std::error_code ec;
  for (const std::string* p : {&files.rss, &files.crd}) {
    if (!fs::is_regular_file(*p, ec)) {
      return Status::Error(path + ": the set's file " + *p + " is missing");
    }
  }
  if (fs::is_regular_file(stem + kSuffixes[2], ec)) files.tms = stem + kSuffixes[2];
  if (fs::is_regular_file(stem + kSuffixes[3], ec)) files.ids = stem + kSuffixes[3];
  return files;
}

bool IsUjiLongTermSet(const std::string& path) { return FindUjiLongTermFiles(path).ok(); }

StatusOr<std::vector<LabelledScan>> ReadUjiLongTermSet(const std::string& path, bool lenient,
                                                       UjiLongTermReport* report) {
  UjiLongTermReport local;
  UjiLongTermReport& r = report ? *report : local;
  r = UjiLongTermReport();
  auto files = FindUjiLongTermFiles(path);
  if (!files.ok()) return files.status();
  Rows rss, crd, tms, ids;
  RATSLAM_RETURN_IF_ERROR(ReadRows(files->rss, "RSS file", &rss));
  RATSLAM_RETURN_IF_ERROR(ReadRows(files->crd, "coordinate file", &crd));
  r.has_times = !files->tms.empty();
  r.has_ids = !files->ids.empty();
  if (r.has_times) RATSLAM_RETURN_IF_ERROR(ReadRows(files->tms, "time file", &tms));
  if (r.has_ids) RATSLAM_RETURN_IF_ERROR(ReadRows(files->ids, "identifier file", &ids));
  if (rss.fields.empty()) return Status::Error(files->rss + ": no rows");
  // Rows pair up by position: a file with another number of rows cannot be aligned, even in
  // lenient mode.
  for (const Rows* other : {&crd, &tms, &ids}) {
    if (other->path.empty() || other->fields.size() == rss.fields.size()) continue;
    return Status::Error(other->path + ": " + std::to_string(other->fields.size()) + " rows, but " +
                         rss.path + " has " + std::to_string(rss.fields.size()) +
                         " (rows pair up line by line)");
  }
  const size_t columns = rss.fields[0].size();
  r.access_points = columns;
  std::vector<LabelledScan> scans;
  for (size_t i = 0; i < rss.fields.size(); ++i) {
    ++r.rows;
    LabelledScan s;
    s.line = rss.lines[i];
    s.time_s = static_cast<double>(i);
    Status status;
    const std::vector<std::string>& f = rss.fields[i];
    if (f.size() != columns) {
      status = RowError(rss, i,
                        "expected " + std::to_string(columns) + " fields (as line " +
                            std::to_string(rss.lines[0]) + "), found " + std::to_string(f.size()) +
                            " (truncated or malformed row)");
    }
    for (size_t k = 0; status.ok() && k < f.size(); ++k) {
      double v = 0;
      if (!ParseNumber(f[k], &v)) {
        status = FieldError(rss, i, FieldName("rss", k), "not a number: '" + f[k] + "'");
      } else if (v != kNotDetected) {
        if (v > 0 || v < -120) {
          status = FieldError(rss, i, FieldName("rss", k), "RSSI out of range: " + f[k]);
        }
        s.readings.push_back({FieldName("rss", k), v});
      }
    }
    const std::vector<std::string>& c = crd.fields[i];
    if (status.ok() && c.size() != 3) {
      status =
          RowError(crd, i, "expected 3 fields (x, y, floor), found " + std::to_string(c.size()));
    }
    double xyf[3] = {};
    for (size_t k = 0; status.ok() && k < 3; ++k) {
      const double limit = k < 2 ? kMaxCoordinateM : kMaxFloor;
      if (!ParseNumber(c[k], &xyf[k])) {
        status = FieldError(crd, i, FieldName("crd", k), "not a number: '" + c[k] + "'");
      } else if (!(std::abs(xyf[k]) <= limit)) {
        status = FieldError(crd, i, FieldName("crd", k), "out of range: " + c[k]);
      } else if (k == 2 && xyf[k] != std::floor(xyf[k])) {
        status = FieldError(crd, i, "floor", "not a whole number: " + c[k]);
      }
    }
    if (status.ok() && r.has_times) status = ParseTime(tms, i, &s.time_s);
    if (status.ok() && r.has_ids) {
      const std::vector<std::string>& d = ids.fields[i];
      for (size_t k = 0; status.ok() && k < d.size(); ++k) {
        double v = 0;
        if (!ParseNumber(d[k], &v) || v != std::floor(v) || !(std::abs(v) <= kMaxId)) {
          status = FieldError(ids, i, "id " + std::to_string(k + 1),
                              "not a whole number of at most 2e9: '" + d[k] + "'");
        } else if (k == 0) {
          s.space = static_cast<int>(v);
        }
      }
    }
    if (!status.ok()) {
      if (!lenient) return status;
      ++r.skipped_malformed;
      continue;
    }
    s.x_m = xyf[0];
    s.y_m = xyf[1];
    s.floor = static_cast<int>(xyf[2]);
    scans.push_back(std::move(s));
  }
  return scans;
}

}  // namespace ratslam::dataset
