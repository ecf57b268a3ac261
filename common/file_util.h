// Writing files so that a reader never sees a half-written one.
#ifndef RATSLAM_COMMON_FILE_UTIL_H_
#define RATSLAM_COMMON_FILE_UTIL_H_

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "common/status.h"

namespace ratslam {

// std::filesystem's questions without its exceptions: a path the system refuses to look up (a
// path longer than PATH_MAX, a file used as a folder, no permission) is simply
// not there. User-given paths go through these, never through the throwing overloads.
bool PathExists(const std::filesystem::path& path) noexcept;
bool IsDirectory(const std::filesystem::path& path) noexcept;
bool IsRegularFile(const std::filesystem::path& path) noexcept;

// Writes `contents` to a temporary file beside `path` (`path.tmp<pid>`, created exclusively and
// never through a symbolic link), flushes it to disk and
// renames it over `path`: the file is either the old one or the complete new one. Temporary
// files that killed writers left in that folder (their process is gone) are removed the first
// time this process writes there.
// With `flush_to_disk` false the data is not fsync'ed (for many small files such as a data set's
// images, where a power cut may lose the newest but a crash never leaves a torn one).
Status WriteFileAtomically(const std::string& path, const std::string& contents,
                           bool flush_to_disk = true);

// Several files that belong together (a run's outputs): every one is first written to its
// temporary file and flushed; only when all of them are on disk are they renamed into place. A
// failure (a full disk) removes the temporary files and leaves every earlier file as it was;
// the error names the file.
Status WriteFilesAtomically(const std::vector<std::pair<std::string, std::string>>& files);

}  // namespace ratslam

#endif  // RATSLAM_COMMON_FILE_UTIL_H_
