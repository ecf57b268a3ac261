#include "common/file_util.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "common/output_folder.h"
#include "common/scratch_dir.h"
#include "common/text_file.h"

namespace ratslam {
namespace {
namespace fs = std::filesystem;

// The file's bytes; empty when it cannot be read.
std::string Slurp(const fs::path& p) {
  StatusOr<std::string> bytes = ReadRegularFile(p.string(), "file", size_t{1} << 30);
  return bytes.ok() ? *bytes : std::string();
}

TEST(FileUtilTest, AFailedWriteOfSeveralFilesKeepsEveryEarlierFile) {
  ScratchDir dir("ratslam_file_util");
  ASSERT_TRUE(WriteFileAtomically((dir / "a.csv").string(), "old a").ok());
  ASSERT_TRUE(WriteFileAtomically((dir / "b.csv").string(), "old b").ok());
  // The third file cannot be created (its folder does not exist): nothing may change.
  const Status status = WriteFilesAtomically({{(dir / "a.csv").string(), "new a"},
                                              {(dir / "b.csv").string(), "new b"},
                                              {(dir / "missing" / "c.csv").string(), "c"}});
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("c.csv"), std::string::npos) << status.message();
  EXPECT_EQ(Slurp(dir / "a.csv"), "old a");
  EXPECT_EQ(Slurp(dir / "b.csv"), "old b");
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << entry.path();
  }
  ASSERT_TRUE(WriteFilesAtomically(
                  {{(dir / "a.csv").string(), "new a"}, {(dir / "b.csv").string(), "new b"}})
                  .ok());
  EXPECT_EQ(Slurp(dir / "a.csv"), "new a");
  EXPECT_EQ(Slurp(dir / "b.csv"), "new b");
}

// A writer killed mid-save leaves `name.tmp<pid>`; the next save removes it when that process is
// gone, and leaves a live writer's file alone.
TEST(FileUtilTest, APlantedLinkAtTheTemporaryNameIsNeverWrittenThrough) {
  ScratchDir dir("ratslam_file_util");
  fs::create_directories(dir / "out");
  ASSERT_TRUE(WriteFileAtomically((dir / "outside.txt").string(), "precious").ok());
  const std::string target = (dir / "out" / "summary.json").string();
  // The name this process's temporary file will have, planted as a link to a file elsewhere.
  fs::create_symlink(dir / "outside.txt", target + ".tmp" + std::to_string(::getpid()));
  ASSERT_TRUE(WriteFileAtomically(target, "{}").ok());
  EXPECT_EQ(Slurp(dir / "outside.txt"), "precious");
  EXPECT_EQ(Slurp(target), "{}");
  EXPECT_FALSE(fs::is_symlink(target));
  fs::create_symlink(dir / "outside.txt", target + ".tmp" + std::to_string(::getpid()));
  ASSERT_TRUE(WriteFileAtomically(target, "{}", /*flush_to_disk=*/false).ok());
  EXPECT_EQ(Slurp(dir / "outside.txt"), "precious");
}

TEST(FileUtilTest, TemporaryFilesOfKilledWritersAreRemoved) {
  ScratchDir dir("ratslam_file_util");
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  ::waitpid(child, nullptr, 0);  // `child` is now a pid that no process has
  const fs::path dead = dir / ("m.map.tmp" + std::to_string(child));
  const fs::path live = dir / ("m.map.tmp" + std::to_string(::getppid()));
  std::ofstream(dead) << "half a map";
  std::ofstream(live) << "being written";
  ASSERT_TRUE(WriteFileAtomically((dir / "m.map").string(), "map").ok());
  EXPECT_FALSE(fs::exists(dead));
  EXPECT_TRUE(fs::exists(live));
  EXPECT_EQ(Slurp(dir / "m.map"), "map");
}

TEST(OutputFolderTest, DiskFolderCreatesItsFolderAndWritesFiles) {
  ScratchDir dir("ratslam_file_util");
  auto folder = DiskFolder::Open((dir / "run" / "nested").string());
  ASSERT_TRUE(folder.ok()) << folder.status().message();
  ASSERT_TRUE((*folder)->Write("x.txt", "x").ok());
  EXPECT_EQ(Slurp(dir / "run" / "nested" / "x.txt"), "x");
  EXPECT_EQ((*folder)->Path("x.txt"), (dir / "run" / "nested" / "x.txt").string());
}

}  // namespace
}  // namespace ratslam
