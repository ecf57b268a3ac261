// Keeps one run's outputs from mixing with another's in an output folder.
//
// A command that writes into a folder (replay, demo, evaluate, locate, call, simulate, import)
// opens an OutputGuard first. A folder that holds an earlier run's outputs (its list,
// `ratslam_outputs.txt`, or one of the files only our runs write, such as summary.json) is
// refused unless the user asked for --overwrite. Other files in the folder are left alone.
//
// After the run, Finish lists every file the run created or changed in `ratslam_outputs.txt`
// (found by comparing the folder before and after, so images and animation frames count too).
// With --overwrite and a successful run, the earlier run's files that this run did not rewrite
// are removed: the folder then holds exactly this run's outputs and the user's own files. The
// earlier files are not removed up front, so a run that fails (a full disk) still leaves the
// earlier run's complete outputs in place.
#ifndef RATSLAM_APPS_OUTPUT_GUARD_H_
#define RATSLAM_APPS_OUTPUT_GUARD_H_

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "common/status.h"

namespace ratslam {

class OutputGuard {
 public:
  static constexpr const char* kListName = "ratslam_outputs.txt";

  // Checks `folder` (which need not exist). `inputs` are paths the run reads (--data,
  // --load-map, --config, ...): they are never removed, even when an earlier run wrote them.
  static StatusOr<OutputGuard> Begin(const std::string& folder, bool overwrite,
                                     const std::vector<std::string>& inputs);

  // Records this run's files and, with --overwrite after a run that `succeeded`, removes the
  // earlier run's files that this run did not write. Returns the files removed.
  StatusOr<std::vector<std::string>> Finish(bool succeeded);

 private:
  struct FileStamp {
    uint64_t inode = 0;
    int64_t mtime_ns = 0;
    uint64_t size = 0;
    bool operator==(const FileStamp&) const = default;
  };
  using Snapshot = std::map<std::string, FileStamp>;  // relative path -> stamp
  static Snapshot Scan(const std::string& folder);

  std::string folder_;
  bool overwrite_ = false;
  std::set<std::string> inputs_;   // relative paths of inputs inside the folder
  std::set<std::string> earlier_;  // the earlier run's outputs (relative paths)
  Snapshot before_;
};

}  // namespace ratslam

#endif  // RATSLAM_APPS_OUTPUT_GUARD_H_
