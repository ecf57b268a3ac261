// Writing files so that a reader never sees a half-written one.
#ifndef RATSLAM_COMMON_FILE_UTIL_H_
#define RATSLAM_COMMON_FILE_UTIL_H_

#include <string>

#include "common/status.h"

namespace ratslam {

// Writes `contents` to a temporary file beside `path`, flushes it to disk and renames it over
// `path`: the file is either the old one or the complete new one.
Status WriteFileAtomically(const std::string& path, const std::string& contents);

}  // namespace ratslam

#endif  // RATSLAM_COMMON_FILE_UTIL_H_
