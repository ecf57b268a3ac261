// Where the tests find the source tree, the shared data sets and the `ratslam` program. The
// paths are compiled into one small library (tests/test_paths.cc) rather than into every test's
// command line, so a clone in another folder recompiles that one file and ccache serves every
// test object from the cache.
#ifndef RATSLAM_TESTS_TEST_PATHS_H_
#define RATSLAM_TESTS_TEST_PATHS_H_

#include <string>

namespace ratslam::test_paths {

std::string SourceDir();      // the clone's top folder
std::string SharedDataDir();  // ../shared/data beside the clone
std::string RatslamBinary();  // the built `ratslam` program

}  // namespace ratslam::test_paths

#endif  // RATSLAM_TESTS_TEST_PATHS_H_
