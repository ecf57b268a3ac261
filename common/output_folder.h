// Where a run or an evaluation writes its files. Sessions write through this small interface, so
// that tests can inject a failing disk (FailingFolder in tests) and every write is checked.
#ifndef RATSLAM_COMMON_OUTPUT_FOLDER_H_
#define RATSLAM_COMMON_OUTPUT_FOLDER_H_

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "common/status.h"

namespace ratslam {

class OutputFolder {
 public:
  virtual ~OutputFolder() = default;
  // The path of `name` in the folder (for messages, and for writers that need a path).
  virtual std::string Path(const std::string& name) const = 0;
  // Writes every file completely, or none of them (see WriteFilesAtomically); an error names the
  // file. Earlier files of the same names are kept on failure.
  virtual Status Write(const std::vector<std::pair<std::string, std::string>>& files) = 0;
  Status Write(const std::string& name, const std::string& contents) {
    return Write({{name, contents}});
  }
};

// A folder on disk (created, with its parents, by Open).
class DiskFolder : public OutputFolder {
 public:
  static StatusOr<std::unique_ptr<DiskFolder>> Open(const std::string& path);
  std::string Path(const std::string& name) const override;
  using OutputFolder::Write;
  Status Write(const std::vector<std::pair<std::string, std::string>>& files) override;

 private:
  explicit DiskFolder(std::string path) : path_(std::move(path)) {}
  std::string path_;
};

}  // namespace ratslam

#endif  // RATSLAM_COMMON_OUTPUT_FOLDER_H_
