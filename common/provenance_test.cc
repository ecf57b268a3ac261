#include "common/provenance.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
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

// Whether `text` matches `pattern`, where '#' stands for a digit, '%' for a lowercase hex digit
// and any other character for itself (std::regex trips GCC 12's warnings under sanitizers).
bool Shaped(const std::string& text, const std::string& pattern) {
  if (text.size() != pattern.size()) return false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i], p = pattern[i];
    const bool digit = c >= '0' && c <= '9';
    if (p == '#' ? !digit : p == '%' ? !(digit || (c >= 'a' && c <= 'f')) : c != p) return false;
  }
  return true;
}

TEST(ProvenanceTest, TimeAndBuildAreWellFormed) {
  EXPECT_TRUE(Shaped(UtcNowIso8601(), "####-##-##T##:##:##Z")) << UtcNowIso8601();
  const std::string version = RatslamVersion();
  EXPECT_EQ(std::count(version.begin(), version.end(), '.'), 2) << version;
  const std::string commit = RatslamCommit();
  EXPECT_TRUE(commit == "unknown" || Shaped(commit, "%%%%%%%%%%%%") ||
              Shaped(commit, "%%%%%%%%%%%%-dirty"))
      << commit;
  EXPECT_FALSE(RatslamBuildType().empty());
}

}  // namespace
}  // namespace ratslam
