#include "common/provenance.h"

#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <string>

#include "common/scratch_dir.h"
#include "common/version.h"

namespace ratslam {
namespace {

TEST(ProvenanceTest, InputsAreSizedFilesAndFolders) {
  ScratchDir dir("provenance_test");
  std::ofstream(dir / "a.txt") << "12345";
  std::filesystem::create_directories(dir / "d" / "e");
  std::ofstream(dir / "d" / "x") << "abc";
  std::ofstream(dir / "d" / "e" / "y") << "abcdefg";
  const auto inputs =
      DescribeInputs({(dir / "a.txt").string(), (dir / "d").string(), (dir / "missing").string()});
  ASSERT_EQ(inputs.size(), 3u);
  EXPECT_EQ(inputs[0].bytes, 5u);
  EXPECT_EQ(inputs[0].files, 1u);
  EXPECT_EQ(inputs[1].bytes, 10u);
  EXPECT_EQ(inputs[1].files, 2u);
  EXPECT_EQ(inputs[2].files, 0u);
  EXPECT_EQ(inputs[2].path, (dir / "missing").string());
}

TEST(ProvenanceTest, CommandLineQuotesWhatAShellWouldSplit) {
  const char* argv[] = {"ratslam", "replay", "--data", "my data/x.txt", "--out", "o'k", ""};
  EXPECT_EQ(ShellCommandLine(7, argv), "ratslam replay --data 'my data/x.txt' --out 'o'\\''k' ''");
}

TEST(ProvenanceTest, TimeAndBuildAreWellFormed) {
  EXPECT_TRUE(std::regex_match(UtcNowIso8601(), std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ)")));
  EXPECT_TRUE(std::regex_match(RatslamVersion(), std::regex(R"(\d+\.\d+\.\d+)")));
  const std::string commit = RatslamCommit();
  EXPECT_TRUE(commit == "unknown" ||
              std::regex_match(commit, std::regex(R"([0-9a-f]{12}(-dirty)?)")))
      << commit;
  EXPECT_FALSE(RatslamBuildType().empty());
}

}  // namespace
}  // namespace ratslam
