// Documentation blocks that the code generates (docs/cli.md's command reference, docs/config.md's
// key tables): a test compares the block between its markers with what the code makes now, so
// the two cannot drift apart; RATSLAM_UPDATE_README=1 rewrites the block instead (then review
// the diff).
#ifndef RATSLAM_TESTS_GENERATED_BLOCK_H_
#define RATSLAM_TESTS_GENERATED_BLOCK_H_

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/test_paths.h"

namespace ratslam::e2e {

// `doc` is relative to the source folder; its block lies between "<!-- `marker`: begin -->\n"
// and "<!-- `marker`: end -->".
inline void ExpectGeneratedBlock(const std::string& doc, const std::string& marker,
                                 const std::string& generated) {
  const std::string path = std::string(ratslam::test_paths::SourceDir()) + "/" + doc;
  std::ifstream in(path);
  ASSERT_TRUE(in) << path << " not found";
  std::stringstream s;
  s << in.rdbuf();
  const std::string text = s.str();
  const std::string begin = "<!-- " + marker + ": begin -->\n";
  const std::string end = "<!-- " + marker + ": end -->";
  const size_t a = text.find(begin);
  const size_t b = text.find(end);
  ASSERT_NE(a, std::string::npos) << path << " has no '" << begin << "' marker";
  ASSERT_NE(b, std::string::npos) << path << " has no '" << end << "' marker";
  if (std::getenv("RATSLAM_UPDATE_README") != nullptr) {
    std::ofstream(path) << text.substr(0, a + begin.size()) << generated << text.substr(b);
    GTEST_SKIP() << path << " rewritten";
  }
  EXPECT_EQ(text.substr(a + begin.size(), b - a - begin.size()), generated)
      << doc << "'s " << marker << " is out of date: rerun this test with RATSLAM_UPDATE_README=1";
}

}  // namespace ratslam::e2e

#endif  // RATSLAM_TESTS_GENERATED_BLOCK_H_
