#include "common/version.h"

#include "ratslam_build_info.h"  // generated in the build tree by cmake/build_info.cmake

namespace ratslam {

std::string RatslamVersion() { return RATSLAM_VERSION; }
std::string RatslamCommit() { return RATSLAM_COMMIT; }
std::string RatslamBuildType() {
  const std::string type = RATSLAM_BUILD_TYPE;
  return type.empty() ? "unspecified" : type;
}

}  // namespace ratslam
