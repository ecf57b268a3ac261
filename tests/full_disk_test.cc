// A full disk, for real: a small tmpfs (mounted where the machine allows it, as root in CI; the
// test skips with a message elsewhere). Writing a data set, a run's outputs or images there must
// fail with an error that names the file, leave no empty or truncated file behind, and keep
// what can be kept (a map saved to another disk).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "common/scratch_dir.h"
#include "io/map_file.h"
#include "tests/run_ratslam.h"
#include "tests/test_paths.h"

namespace ratslam {
namespace {
namespace fs = std::filesystem;

using e2e::Result;
using e2e::RunRatslam;

class FullDiskTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (::geteuid() != 0) GTEST_SKIP() << "needs root to mount a small tmpfs";
    disk_ = scratch_ / "disk";
    fs::create_directories(disk_);
    const std::string mount =
        "mount -t tmpfs -o size=192k tmpfs " + disk_.string() + " 2>/dev/null";
    if (std::system(mount.c_str()) != 0) GTEST_SKIP() << "mount -t tmpfs is not permitted here";
    mounted_ = true;
  }
  void TearDown() override {
    if (mounted_) (void)std::system(("umount " + disk_.string()).c_str());
  }
  // Every regular file under `folder` is non-empty (no 0-byte or left-over temporary file).
  static void ExpectNoEmptyOrTemporaryFiles(const fs::path& folder) {
    for (const auto& entry : fs::recursive_directory_iterator(folder)) {
      if (!entry.is_regular_file()) continue;
      EXPECT_GT(entry.file_size(), 0u) << entry.path();
      EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
    }
  }
  ScratchDir scratch_{"ratslam_full_disk"};
  fs::path disk_;
  bool mounted_ = false;
};

TEST_F(FullDiskTest, SimulateFailsNamingTheFileAndLeavesNoEmptyFile) {
  const Result r = RunRatslam(
      "simulate --quiet --world apartment --out " + (disk_ / "data").string(), scratch_.path());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find((disk_ / "data").string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("No space left"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(disk_ / "data" / "manifest.toml"));  // never reads as complete
  ExpectNoEmptyOrTemporaryFiles(disk_);
}

TEST_F(FullDiskTest, ReplayOutputsFailButTheMapIsSavedElsewhere) {
  const fs::path data = scratch_ / "data";
  ASSERT_EQ(RunRatslam("simulate --quiet --world apartment --out " + data.string(), scratch_.path())
                .exit_code,
            0);
  // Fill the small disk almost completely, so that the outputs cannot fit.
  (void)std::system(("head -c 150000 /dev/zero > " + (disk_ / "filler").string()).c_str());
  const fs::path map = scratch_ / "elsewhere.map";
  const std::string config =
      std::string(ratslam::test_paths::SourceDir()) + "/configs/sim-fused.toml";
  const Result r =
      RunRatslam("replay --quiet --config " + config + " --data " + data.string() + " --out " +
                     (disk_ / "run").string() + " --save-map " + map.string(),
                 scratch_.path());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("No space left"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find((disk_ / "run").string()), std::string::npos) << r.err;
  ASSERT_TRUE(fs::exists(map)) << r.err;
  EXPECT_TRUE(io::LoadMapFile(map.string()).ok());
  EXPECT_FALSE(fs::exists(disk_ / "run" / "summary.json"));  // all outputs or none
  ExpectNoEmptyOrTemporaryFiles(disk_);
}

}  // namespace
}  // namespace ratslam
