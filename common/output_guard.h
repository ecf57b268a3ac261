// Keeps one run's outputs from mixing with another's in an output folder.
//
// A command that writes into a folder (replay, demo, evaluate, locate, call, simulate, import)
// opens an OutputGuard first:
// - It locks the folder (flock on `.ratslam.lock`, which names the holder): a second run into
//   the same folder fails at once, naming the first.
// - A folder that holds an earlier run's outputs (its list, `ratslam_outputs.txt`, or one of the
//   files only our runs write, such as summary.json) is refused unless the user asked for
//   --overwrite. Other files in the folder are left alone.
// - The run writes into a staging folder inside it (`staging()`), never into the folder itself.
//
// Finish makes the run's outputs appear together. After a run that succeeded or was
// interrupted cleanly, it writes a journal (`.ratslam-commit`) naming every staged file and
// every earlier-run file to remove, then moves the staged files into place and removes those,
// then removes the journal. A process killed in between leaves the journal, and the next guard on
// the folder (or RecoverOutputFolder, which readers of run folders call) completes the moves:
// the folder then holds exactly the new run's outputs, never a mixture. A run killed before
// Finish leaves only its staging folder, which the next guard removes; the earlier outputs were
// never touched.
//
// After a failed run nothing in the folder changes; what the run did write is kept in
// `incomplete-run/` for the user to look at (the next failed run replaces it, the next
// successful one removes it). With --overwrite and a successful run, the earlier run's files
// that this run did not write again are removed: the folder then holds exactly this run's
// outputs and the user's own files. `ratslam_outputs.txt` lists the run's files.
#ifndef RATSLAM_COMMON_OUTPUT_GUARD_H_
#define RATSLAM_COMMON_OUTPUT_GUARD_H_

#include <set>
#include <string>
#include <utility>
#include <vector>

#include "common/status.h"

namespace ratslam {

// An exclusive lock on a folder (flock on its `.ratslam.lock`, which names the holder), held for
// the object's life. A sweep folder is locked this way while `sweep run` works in it.
class FolderLock {
 public:
  // Locks `folder` (which must exist) without waiting; the error names the holder.
  static StatusOr<FolderLock> Acquire(const std::string& folder, const std::string& holder);
  FolderLock(FolderLock&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  FolderLock& operator=(FolderLock&& other) noexcept;
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;
  ~FolderLock();

 private:
  explicit FolderLock(int fd) : fd_(fd) {}
  int fd_ = -1;
};

class OutputGuard {
 public:
  static constexpr const char* kListName = "ratslam_outputs.txt";
  static constexpr const char* kLockName = ".ratslam.lock";
  static constexpr const char* kStagingName = ".ratslam-staging";
  static constexpr const char* kJournalName = ".ratslam-commit";
  static constexpr const char* kIncompleteName = "incomplete-run";

  enum class Outcome {
    kSucceeded,    // the run finished: its outputs replace the earlier run's
    kInterrupted,  // stopped early (by the user, or by bad data) after writing consistent
                   // outputs, its summary among them: as kSucceeded
    kFailed,       // the folder is left as it was; the staged files go to incomplete-run/
  };
  struct Report {
    std::vector<std::string> removed;  // earlier-run files removed (relative paths)
    std::string incomplete;            // where a failed run's files were kept; empty: none
  };

  // Locks and checks `folder` (created if it does not exist). `inputs` are paths the run reads
  // (--data, --load-map, --config, ...): they are never removed, even when an earlier run wrote
  // them. `holder` describes this run in the lock file (a command line) for a refused second run.
  static StatusOr<OutputGuard> Begin(const std::string& folder, bool overwrite,
                                     const std::vector<std::string>& inputs,
                                     const std::string& holder = "");

  OutputGuard(OutputGuard&& other) noexcept;
  OutputGuard& operator=(OutputGuard&& other) noexcept;
  OutputGuard(const OutputGuard&) = delete;
  OutputGuard& operator=(const OutputGuard&) = delete;
  ~OutputGuard();  // releases the lock; a staging folder left behind is removed by the next guard

  // The folder the run writes into instead of the output folder (empty before Begin).
  const std::string& staging() const { return staging_; }
  // `path` moved into the staging folder when it lies inside the output folder (an output named
  // by its own flag, such as --save-map); any other path as it is.
  std::string Staged(const std::string& path) const;

  // Whether the run has written its summary (summary.json, evaluation.json, ...) into the
  // staging folder: a run that stopped on an error after that has consistent outputs to keep.
  bool StagedSummary() const;

  // Moves the staged outputs into place (or, after a failed run, aside) as described above, and
  // releases the lock. Called once.
  StatusOr<Report> Finish(Outcome outcome);

 private:
  OutputGuard() = default;

  std::string folder_;
  std::string staging_;
  bool overwrite_ = false;
  bool created_folder_ = false;  // Begin created the folder: Finish removes it if left empty
  int lock_fd_ = -1;
  std::set<std::string> inputs_;   // relative paths of inputs inside the folder
  std::set<std::string> earlier_;  // the earlier run's outputs (relative paths)
};

// An output named by its own flag (`flag` F, such as --save-map): refused when F exists and
// `overwrite` is false, so that a run never replaces a file the user did not ask it to. Ok for an
// empty path.
Status CheckReplaceable(const std::string& path, bool overwrite, const std::string& flag);

// Completes the commit that a run killed while moving its outputs into place left in `folder`
// (its journal), under the folder's lock. Readers of run folders call it first, so that they
// never read a mixture of two runs. Ok when there is nothing to complete; an error names the
// folder when it is locked by a run still going or cannot be written.
Status RecoverOutputFolder(const std::string& folder);

}  // namespace ratslam

#endif  // RATSLAM_COMMON_OUTPUT_GUARD_H_
