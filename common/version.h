// What build of the program this is, for provenance (summary.json's `run` object) and
// `ratslam --version`.
#ifndef RATSLAM_COMMON_VERSION_H_
#define RATSLAM_COMMON_VERSION_H_

#include <string>

namespace ratslam {

// The project version (CMake's project VERSION).
std::string RatslamVersion();
// The git commit the program was built from (12 hex digits, "-dirty" when the working tree had
// uncommitted changes to tracked files), or "unknown" outside a git checkout.
std::string RatslamCommit();
// CMake's build type (Release, Debug, ...), or "unspecified".
std::string RatslamBuildType();

}  // namespace ratslam

#endif  // RATSLAM_COMMON_VERSION_H_
