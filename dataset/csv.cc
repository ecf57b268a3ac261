#include "dataset/csv.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "common/text_file.h"

namespace ratslam::dataset {
namespace {

std::vector<std::string> SplitFields(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream stream(line);
  while (std::getline(stream, field, ',')) {
    // Trim spaces and a trailing carriage return (files written on Windows).
    const auto begin = field.find_first_not_of(" \t\r");
    const auto end = field.find_last_not_of(" \t\r");
    fields.push_back(begin == std::string::npos ? "" : field.substr(begin, end - begin + 1));
  }
  if (!line.empty() && line.back() == ',') fields.push_back("");
  return fields;
}

}  // namespace

StatusOr<CsvTable> CsvTable::Read(const std::string& path, const std::vector<std::string>& required,
                                  const std::vector<std::string>& optional) {
  std::ifstream in;
  RATSLAM_RETURN_IF_ERROR(OpenRegularFile(path, "file", &in));
  CsvTable table;
  table.path_ = path;
  std::string line;
  int line_number = 0;
  bool have_header = false;
  for (;;) {
    const LineResult read = ReadLine(in, &line);
    if (read == LineResult::kEnd) break;
    ++line_number;
    if (read == LineResult::kTooLong) {
      return Status::Error(path + ":" + std::to_string(line_number) + ": line longer than " +
                           std::to_string(kMaxLineBytes) + " bytes");
    }
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;  // blank line
    if (line[line.find_first_not_of(" \t")] == '#') continue;            // comment
    std::vector<std::string> fields = SplitFields(line);
    if (!have_header) {
      for (size_t i = 0; i < fields.size(); ++i) {
        const std::string& name = fields[i];
        const bool known = std::find(required.begin(), required.end(), name) != required.end() ||
                           std::find(optional.begin(), optional.end(), name) != optional.end();
        if (!known) {
          return Status::Error(path + ":" + std::to_string(line_number) + ": unknown column '" +
                               name + "'");
        }
        if (!table.columns_.emplace(name, i).second) {
          return Status::Error(path + ":" + std::to_string(line_number) + ": column '" + name +
                               "' appears twice");
        }
      }
      for (const std::string& name : required) {
        if (!table.columns_.count(name)) {
          return Status::Error(path + ":" + std::to_string(line_number) +
                               ": missing required column '" + name + "'");
        }
      }
      have_header = true;
      continue;
    }
    if (fields.size() != table.columns_.size()) {
      return Status::Error(path + ":" + std::to_string(line_number) + ": expected " +
                           std::to_string(table.columns_.size()) + " fields, found " +
                           std::to_string(fields.size()) + " (truncated or malformed row)");
    }
    table.fields_.push_back(std::move(fields));
    table.lines_.push_back(line_number);
  }
  if (in.bad()) return Status::Error(path + ": read error");
  if (!have_header) return Status::Error(path + ": empty file (no header row)");
  return table;
}

Status CsvTable::ErrorAt(size_t row, const std::string& column, const std::string& message) const {
  return Status::Error(path_ + ":" + std::to_string(lines_[row]) + ": column '" + column +
                       "': " + message);
}

StatusOr<double> CsvTable::Number(size_t row, const std::string& column) const {
  const std::string& text = fields_[row][columns_.at(column)];
  double value = 0.0;
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  const auto result = std::from_chars(begin, end, value);
  if (text.empty() || result.ec != std::errc() || result.ptr != end) {
    return ErrorAt(row, column, "not a number: '" + text + "'");
  }
  if (!std::isfinite(value)) return ErrorAt(row, column, "not finite: '" + text + "'");
  if (std::abs(value) > kMaxCsvMagnitude) {
    return ErrorAt(row, column, "out of range (magnitude above 1e12): '" + text + "'");
  }
  return value;
}

StatusOr<std::string> CsvTable::Text(size_t row, const std::string& column) const {
  const std::string& text = fields_[row][columns_.at(column)];
  if (text.empty()) return ErrorAt(row, column, "empty field");
  return text;
}

}  // namespace ratslam::dataset
