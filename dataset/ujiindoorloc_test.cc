#include "dataset/ujiindoorloc.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/scratch_dir.h"
#include "tests/test_paths.h"

namespace ratslam::dataset {
namespace {

// One fresh folder per test process (two checkouts testing at once never collide).
const ScratchDir& TestScratch() {
  static const ScratchDir dir("ratslam_test");
  return dir;
}
namespace fs = std::filesystem;

const char kHeader[] =
    "WAP001,WAP002,WAP003,LONGITUDE,LATITUDE,FLOOR,BUILDINGID,SPACEID,"
    "RELATIVEPOSITION,USERID,PHONEID,TIMESTAMP\n";

fs::path Write(const std::string& name, const std::string& text) {
  const fs::path p = TestScratch().path() / name;
  std::ofstream(p) << text;
  return p;
}

TEST(UjiIndoorLocTest, NotDetectedIsDropped) {
  const fs::path p =
      Write("ratslam_uji.csv",
            std::string(kHeader) + "100,-71,100,-7541.26,4864920.77,2,1,106,2,2,23,1371713733\n");
  StatusOr<std::vector<LabelledScan>> scans = ReadUjiIndoorLoc(p.string());
  ASSERT_TRUE(scans.ok()) << scans.status().message();
  ASSERT_EQ(scans->size(), 1u);
  ASSERT_EQ((*scans)[0].readings.size(), 1u);
  EXPECT_EQ((*scans)[0].readings[0].bssid, "WAP002");
  EXPECT_EQ((*scans)[0].readings[0].rssi_dbm, -71);
  EXPECT_EQ((*scans)[0].floor, 2);
  EXPECT_EQ((*scans)[0].building, 1);
  EXPECT_DOUBLE_EQ((*scans)[0].x_m, -7541.26);
  fs::remove(p);
}

TEST(UjiIndoorLocTest, BrokenRowsNameLineAndColumn) {
  const fs::path p =
      Write("ratslam_uji_bad.csv",
            std::string(kHeader) + "100,-71,100,-7541.26,4864920.77,2,1,106,2,2,23,1\n" +
                "100,abc,100,-7541.26,4864920.77,2,1,106,2,2,23,1\n" + "100,-71\n");
  StatusOr<std::vector<LabelledScan>> strict = ReadUjiIndoorLoc(p.string());
  ASSERT_FALSE(strict.ok());
  EXPECT_NE(strict.status().message().find("ratslam_uji_bad.csv:3: column 'WAP002': not a number"),
            std::string::npos)
      << strict.status().message();
  UjiReadReport report;
  StatusOr<std::vector<LabelledScan>> lenient = ReadUjiIndoorLoc(p.string(), true, &report);
  ASSERT_TRUE(lenient.ok());
  EXPECT_EQ(lenient->size(), 1u);
  EXPECT_EQ(report.skipped_malformed, 2u);
  fs::remove(p);
  const fs::path q = Write("ratslam_uji_col.csv", "WAP001,LONGITUDE,LATITUDE,FLOR,BUILDINGID\n");
  EXPECT_NE(ReadUjiIndoorLoc(q.string()).status().message().find("unknown column 'FLOR'"),
            std::string::npos);
  fs::remove(q);
}

// A floor of 1e300 was cast to int (undefined; found by the fuzzer); ids must be whole numbers.
TEST(UjiIndoorLocTest, OutOfRangeAndFractionalLabelsAreRefused) {
  const std::pair<const char*, const char*> cases[] = {
      {"100,-71,100,-7541.26,4864920.77,1e300,1,106,2,2,23,1\n", "column 'FLOOR': out of range"},
      {"100,-71,100,-7541.26,4864920.77,2.5,1,106,2,2,23,1\n", "'FLOOR': not a whole number"},
      {"100,-71,100,-7541.26,4864920.77,2,1,106,2,2,23,-5\n", "'TIMESTAMP': negative time"},
  };
  for (const auto& [row, expected] : cases) {
    const fs::path p = Write("ratslam_uji_range.csv", std::string(kHeader) + row);
    StatusOr<std::vector<LabelledScan>> scans = ReadUjiIndoorLoc(p.string());
    ASSERT_FALSE(scans.ok()) << row;
    EXPECT_NE(scans.status().message().find("ratslam_uji_range.csv:2: "), std::string::npos);
    EXPECT_NE(scans.status().message().find(expected), std::string::npos)
        << scans.status().message();
  }
}

TEST(UjiIndoorLocTest, RealTrainingFile) {
  const fs::path p =
      fs::path(ratslam::test_paths::SharedDataDir()) / "ujiindoorloc" / "trainingData.csv";
  if (!fs::exists(p)) GTEST_SKIP() << "missing " << p;
  UjiReadReport report;
  StatusOr<std::vector<LabelledScan>> scans = ReadUjiIndoorLoc(p.string(), false, &report);
  ASSERT_TRUE(scans.ok()) << scans.status().message();
  EXPECT_EQ(scans->size(), 19937u);
  EXPECT_EQ(report.access_points, 520u);
}

}  // namespace
}  // namespace ratslam::dataset
