#include "dataset/msft_log.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "common/scratch_dir.h"
#include "dataset/dataset_loader.h"
#include "tests/test_paths.h"

namespace ratslam::dataset {
namespace {

// One fresh folder per test process (two checkouts testing at once never collide).
const ScratchDir& TestScratch() {
  static const ScratchDir dir("ratslam_test");
  return dir;
}
namespace fs = std::filesystem;

const char kFixture[] =
    "#\tstartTime:1574559495255\n"
    "#\tSiteID:x\tSiteName:y\tFloorId:z\tFloorName:F2\n"
    "1574559495260\tTYPE_DIST1\t19.3\t8.2\t-5.5\n"
    "1574559495263\tTYPE_WAYPOINT\t81.317215\t93.31349\n"
    "1574559495401\tTYPE_ROTATION_VECTOR\t0.0\t0.0\t0.0\t3\n"
    "1574559495410\tTYPE_ACCELEROMETER\t0.1\t0.2\t9.8\t3\n"
    "1574559497191\tTYPE_WIFI\tFMI\ta8:0c:ca:03:9d:d7\t-49\t2422\t1574559495450\n"
    "1574559497191\tTYPE_WIFI\tIPC\t74:ee:2a:cd:eb:43\t-53\t2427\t1574559470000\n"
    "1574559503836\tTYPE_WAYPOINT\t75.371765\t94.800575\n";

TEST(MicrosoftLogTest, ReadsScansWaypointsAndFloor) {
  const fs::path path = TestScratch().path() / "ratslam_msft_fixture.txt";
  std::ofstream(path) << kFixture;
  StatusOr<Dataset> d = ReadMicrosoftLog(path.string(), {});
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_EQ(d->wifi.size(), 1u);
  ASSERT_EQ(d->wifi[0].readings.size(), 1u) << "the reading last seen 27 s earlier is stale";
  EXPECT_EQ(d->wifi[0].readings[0].bssid, "a8:0c:ca:03:9d:d7");
  EXPECT_NEAR(d->wifi[0].time_s, 1.936, 1e-9);
  ASSERT_EQ(d->ground_truth.size(), 2u);
  EXPECT_FLOAT_EQ(d->ground_truth[1].x_m, 75.371765);
  EXPECT_EQ(d->ground_truth[0].floor, 1);  // F2
  ASSERT_EQ(d->compass.size(), 1u);
  EXPECT_NEAR(d->compass[0].heading_rad, M_PI / 2, 1e-12);  // identity: y axis points north
  EXPECT_EQ(DetectDatasetFormat(path.string()).value(), DatasetFormat::kMicrosoftLog);
  fs::remove(path);
}

TEST(MicrosoftLogTest, BrokenLineNamesFileAndLine) {
  const fs::path path = TestScratch().path() / "ratslam_msft_broken.txt";
  std::ofstream(path) << kFixture << "1574559503900\tTYPE_WAYPOINT\t75.3\n";
  StatusOr<Dataset> d = ReadMicrosoftLog(path.string(), {});
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.status().message().find("ratslam_msft_broken.txt:10: TYPE_WAYPOINT: missing field"),
            std::string::npos)
      << d.status().message();
  PhoneLogOptions lenient;
  lenient.lenient = true;
  PhoneLogReport report;
  ASSERT_TRUE(ReadMicrosoftLog(path.string(), lenient, &report).ok());
  EXPECT_EQ(report.skipped_malformed, 1u);
  fs::remove(path);
}

// Timestamps before the walk's start once gave negative times, and huge ones minus infinity.
TEST(MicrosoftLogTest, TimesBeforeTheStartAndHugeValuesAreRefused) {
  const std::pair<const char*, const char*> cases[] = {
      {"1574559400000\tTYPE_WAYPOINT\t75.3\t94.8\n", "is before the walk's start time"},
      {"-1e308\tTYPE_WAYPOINT\t75.3\t94.8\n", "field 1 is out of range"},
      {"1574559503900\tTYPE_WAYPOINT\t1e300\t94.8\n", "field 3 is out of range"},
      {"1574559503900\tTYPE_WIFI\tx\taa:bb\t-50\t2412\t-1e300\n", "field 7 is out of range"},
  };
  for (const auto& [line, expected] : cases) {
    const fs::path path = TestScratch().path() / "ratslam_msft_range.txt";
    std::ofstream(path) << kFixture << line;
    StatusOr<Dataset> d = ReadMicrosoftLog(path.string(), {});
    ASSERT_FALSE(d.ok()) << line;
    EXPECT_NE(d.status().message().find("ratslam_msft_range.txt:10: "), std::string::npos)
        << d.status().message();
    EXPECT_NE(d.status().message().find(expected), std::string::npos) << d.status().message();
  }
}

TEST(MicrosoftLogTest, FloorNamesAndRotationVectors) {
  EXPECT_EQ(FloorFromName("B1"), -1);
  EXPECT_EQ(FloorFromName("F1"), 0);
  EXPECT_EQ(FloorFromName("F4"), 3);
  EXPECT_EQ(FloorFromName("B1000"), -1000);
  EXPECT_EQ(FloorFromName("B9496900"), std::nullopt);  // found by the fuzzer: not a floor
  EXPECT_FALSE(FloorFromName("L1").has_value());
  EXPECT_FALSE(FloorFromName("F").has_value());
  // Rotated 90 degrees counter-clockwise about up: the y axis points west.
  const double s = std::sin(M_PI / 4);
  EXPECT_NEAR(HeadingFromRotationVector(0, 0, s), M_PI, 1e-9);
}

TEST(MicrosoftLogTest, RealWalkHasWifiAndWaypoints) {
  const fs::path folder = fs::path(ratslam::test_paths::SharedDataDir()) / "msft-ilc20-site1" /
                          "F1" / "path_data_files";
  if (!fs::exists(folder)) GTEST_SKIP() << "missing " << folder;
  const fs::path walk = *fs::directory_iterator(folder);
  StatusOr<Dataset> d = LoadDataset(walk.string(), {});
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_GT(d->wifi.size(), 5u);
  EXPECT_GE(d->ground_truth.size(), 2u);
  EXPECT_EQ(d->ground_truth[0].floor, 0);
}

}  // namespace
}  // namespace ratslam::dataset
