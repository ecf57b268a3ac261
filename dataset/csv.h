// A strict reader for the replay format's CSV files: a header row of column names, then rows of
// comma-separated fields. Every error names the file, the line and the column.
#ifndef RATSLAM_DATASET_CSV_H_
#define RATSLAM_DATASET_CSV_H_

#include <map>
#include <string>
#include <vector>

#include "common/status.h"

namespace ratslam::dataset {

// No number in a data set is larger: metres, seconds (epoch times included), dBm and radians all
// stay far below it, and anything beyond is corruption that would overflow later arithmetic.
inline constexpr double kMaxCsvMagnitude = 1e12;

class CsvTable {
 public:
  // Reads `path` (a regular file; lines of at most kMaxLineBytes). `required` columns must be
  // present; `optional` ones may be; any other column is an error (a typo in a column name must not
  // be silently ignored).
  static StatusOr<CsvTable> Read(const std::string& path, const std::vector<std::string>& required,
                                 const std::vector<std::string>& optional = {});

  size_t rows() const { return fields_.size(); }
  bool has_column(const std::string& name) const { return columns_.count(name) > 0; }
  int line(size_t row) const { return lines_[row]; }  // 1-based line in the file
  const std::string& path() const { return path_; }

  // The field as a finite number of magnitude at most kMaxCsvMagnitude, or an error naming
  // file, line and column.
  StatusOr<double> Number(size_t row, const std::string& column) const;
  StatusOr<std::string> Text(size_t row, const std::string& column) const;
  // "path:line: column 'name': message".
  Status ErrorAt(size_t row, const std::string& column, const std::string& message) const;

 private:
  std::string path_;
  std::map<std::string, size_t> columns_;
  std::vector<std::vector<std::string>> fields_;
  std::vector<int> lines_;
};

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_CSV_H_
