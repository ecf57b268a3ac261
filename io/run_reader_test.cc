#include "io/run_reader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "common/scratch_dir.h"

namespace ratslam::io {
namespace {

namespace fs = std::filesystem;

std::string WriteFile(const std::string& name, const std::string& text) {
  static const ScratchDir dir("run_reader_test");
  const fs::path path = dir / name;
  std::ofstream(path) << text;
  return path.string();
}

TEST(ReadTumTrajectoryTest, ReadsPosesAndYaw) {
  // Yaw pi/2 about z: q = (0, 0, sin(pi/4), cos(pi/4)); a general quaternion of yaw -0.3.
  const double h = std::sin(std::numbers::pi / 4);
  const std::string path =
      WriteFile("ok_tum.txt",
                "# timestamp tx ty tz qx qy qz qw\n\n0.5 1 2 0 0 0 0 1\n1.5 -3 4.25 9 0 0 " +
                    std::to_string(h) + " " + std::to_string(h) + "\n2 0 0 0 0 0 " +
                    std::to_string(std::sin(-0.15)) + " " + std::to_string(std::cos(-0.15)) + "\n");
  StatusOr<std::vector<GroundTruthRow>> rows = ReadTumTrajectory(path);
  ASSERT_TRUE(rows.ok()) << rows.status().message();
  ASSERT_EQ(rows->size(), 3u);
  EXPECT_EQ((*rows)[0].time_s, 0.5);
  EXPECT_EQ((*rows)[0].x_m, 1.0);
  EXPECT_EQ((*rows)[0].theta_rad, 0.0);
  EXPECT_EQ((*rows)[1].y_m, 4.25);
  EXPECT_NEAR((*rows)[1].theta_rad, std::numbers::pi / 2, 1e-5);
  EXPECT_NEAR((*rows)[2].theta_rad, -0.3, 1e-5);
}

TEST(ReadTumTrajectoryTest, BadFilesNameLineAndField) {
  struct Case {
    const char* text;
    const char* expected;
  };
  const Case cases[] = {
      {"0 1 2 0 0 0 0\n", ":1: field 'qw' missing"},
      {"0 1 2 0 0 0 0 1\n1 nan 2 0 0 0 0 1\n", ":2: field 'tx' is not a finite number"},
      {"0 1 2 0 0 0 0 1\n1 1x 2 0 0 0 0 1\n", ":2: field 'tx' is not a finite number"},
      {"1 1 2 0 0 0 0 1\n# c\n0.5 1 2 0 0 0 0 1\n", ":3: field 'timestamp' is not after"},
      {"1 1 2 0 0 0 0 1\n1 1 2 0 0 0 0 1\n", ":2: field 'timestamp' is not after"},
      {"0 1 2 0 0 0 0 1 5\n", ":1: more than 8 fields"},
      {"# only a comment\n", "no pose"},
  };
  int k = 0;
  for (const Case& c : cases) {
    const std::string path = WriteFile("bad_tum_" + std::to_string(k++) + ".txt", c.text);
    StatusOr<std::vector<GroundTruthRow>> rows = ReadTumTrajectory(path);
    ASSERT_FALSE(rows.ok()) << c.text;
    EXPECT_NE(rows.status().message().find(path), std::string::npos) << rows.status().message();
    EXPECT_NE(rows.status().message().find(c.expected), std::string::npos)
        << rows.status().message();
  }
  EXPECT_FALSE(ReadTumTrajectory(WriteFile("missing_dir_tum", "") + "/nope.txt").ok());
}

}  // namespace
}  // namespace ratslam::io
