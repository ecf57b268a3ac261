#include "tests/test_paths.h"

namespace ratslam::test_paths {

std::string SourceDir() { return RATSLAM_SOURCE_DIR; }
std::string SharedDataDir() { return RATSLAM_SHARED_DATA_DIR; }
std::string RatslamBinary() { return RATSLAM_BINARY; }

}  // namespace ratslam::test_paths
