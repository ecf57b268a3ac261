// Where a run came from, for the `run` object of summary.json and evaluation.json: the build
// (common/version.h), the command line, the start time and the inputs with their sizes.
#ifndef RATSLAM_COMMON_PROVENANCE_H_
#define RATSLAM_COMMON_PROVENANCE_H_

#include <cstdint>
#include <string>
#include <vector>

namespace ratslam {

struct InputDescription {
  std::string path;    // as given
  uint64_t bytes = 0;  // of the file, or of every regular file under the folder
  uint64_t files = 0;  // 1 for a file; the regular files under a folder; 0 if unreadable
};

// Each path's size (folders recursively, symbolic links not followed); an unreadable path is
// listed with 0 files.
std::vector<InputDescription> DescribeInputs(const std::vector<std::string>& paths);

// The current UTC time as ISO 8601 with seconds, e.g. "2026-12-02T10:57:03Z".
std::string UtcNowIso8601();

// argv joined by spaces, each argument single-quoted for a POSIX shell when it holds anything
// but letters, digits and -_./=:,+@%.
std::string ShellCommandLine(int argc, const char* const* argv);

struct RunProvenance {
  std::string command_line;  // empty when the run did not come from a command line
  std::string started_utc;   // empty: unknown
  // A run under an OutputGuard writes into a staging folder that becomes the output folder at
  // its end: paths below `staging_folder` are recorded as below `output_folder` (a demo's data
  // set, simulated into the staging folder, is named where it will be).
  std::string staging_folder;
  std::string output_folder;

  // `path` as the run's outputs name it (see staging_folder).
  std::string Recorded(const std::string& path) const;
};

}  // namespace ratslam

#endif  // RATSLAM_COMMON_PROVENANCE_H_
