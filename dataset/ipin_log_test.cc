#include "dataset/ipin_log.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

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
    "% LogFile created by the 'GetSensorData' App for Android.\n"
    "%\n"
    "ACCE;0.10;100.10;0.1;0.2;9.8;3\n"
    "AHRS;0.11;100.11;1.0;2.0;90.0;0.1;0.2;0.3;3\n"
    "WIFI;0.50;100.50;net;aa:bb;2437;-60\n"
    "WIFI;0.50;100.50;net;cc:dd;5200;-71;\n"
    "WIFI;4.50;104.50;net;aa:bb;-62\n"  // no Frequency column: accepted
    "SOUN;0.6;1;2;3\n"
    "POSI;1.0;1;49.461316433032;11.110964442580;0;100\n"
    "POSI;3.0;2;49.461275602490;11.110988346746;0;100\n";

fs::path WriteFixture(const std::string& name, const std::string& text) {
  const fs::path path = TestScratch().path() / name;
  std::ofstream(path) << text;
  return path;
}

// The log read with malformed lines skipped and counted in `report`.
StatusOr<Dataset> ReadLeniently(const fs::path& path, PhoneLogReport* report) {
  PhoneLogOptions lenient;
  lenient.lenient = true;
  return ReadIpinLog(path.string(), lenient, report);
}

TEST(IpinLogTest, ReadsScansCompassAndGroundTruth) {
  const fs::path path = WriteFixture("ratslam_ipin_fixture.txt", kFixture);
  PhoneLogReport report;
  StatusOr<Dataset> d = ReadIpinLog(path.string(), {}, &report);
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_EQ(d->wifi.size(), 2u);
  ASSERT_EQ(d->wifi[0].readings.size(), 2u);
  EXPECT_EQ(d->wifi[0].readings[1].bssid, "cc:dd");
  EXPECT_EQ(d->wifi[1].readings[0].rssi_dbm, -62);
  ASSERT_EQ(d->compass.size(), 1u);
  // Yaw 90 deg counter-clockwise from north is west: pi from east.
  EXPECT_NEAR(std::abs(d->compass[0].heading_rad), M_PI, 1e-12);
  ASSERT_EQ(d->ground_truth.size(), 2u);
  EXPECT_EQ(d->ground_truth[0].x_m, 0.0);
  // Second point: 0.0000408 deg south, 0.0000239 deg east of the first.
  EXPECT_NEAR(d->ground_truth[1].y_m, -(49.461316433032 - 49.461275602490) * M_PI / 180 * 6371008.8,
              1e-6);
  EXPECT_GT(d->ground_truth[1].x_m, 1.0);
  EXPECT_EQ(report.skipped_other_types, 1u);
  EXPECT_EQ(DetectDatasetFormat(path.string()).value(), DatasetFormat::kIpinLog);
  fs::remove(path);
}

TEST(IpinLogTest, BrokenLinesNameFileAndLineOrAreCountedWhenLenient) {
  std::string text = kFixture;
  text += "WIFI;5.0;105.0;net;aa:bb;2437;strong\n";  // line 11
  text += "ACCE;5.1;105.1;0.1\n";                    // line 12: truncated
  const fs::path path = WriteFixture("ratslam_ipin_broken.txt", text);
  StatusOr<Dataset> strict = ReadIpinLog(path.string(), {});
  ASSERT_FALSE(strict.ok());
  EXPECT_NE(
      strict.status().message().find("ratslam_ipin_broken.txt:11: WIFI: RSS(dBm) is not a number"),
      std::string::npos)
      << strict.status().message();
  PhoneLogReport report;
  StatusOr<Dataset> d = ReadLeniently(path, &report);
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_EQ(report.skipped_malformed, 2u);
  EXPECT_EQ(d->wifi.size(), 2u);
  fs::remove(path);
  EXPECT_FALSE(ReadIpinLog("/nonexistent.txt", {}).ok());
}

// Lines that are not of the TYPE;... shape (random bytes, NULs, a line cut before its first ';')
// once counted as "other sensor types" and the log loaded: now they are errors naming the line,
// or counted as malformed with lenient reading.
TEST(IpinLogTest, LinesThatAreNotSensorLinesAreErrors) {
  std::string garbage;
  uint32_t state = 12345;
  for (int i = 0; i < 4000; ++i) {
    state = state * 1103515245u + 12345u;
    const char c = static_cast<char>((state >> 16) & 0xFF);
    garbage += c == '\n' ? 'x' : c;
  }
  const std::vector<std::pair<std::string, std::string>> cases = {
      {garbage + "\n", "not a sensor line of the form TYPE;..."},
      {std::string(10000, '\0') + "\n", "(it starts '\\x00\\x00"},
      {"GYR\n", "(it starts 'GYR')"},
      {"wifi;0.5;1;net;aa:bb;-60\n", "(it starts 'wifi;"},
  };
  for (const auto& [inserted, expected] : cases) {
    std::string text = kFixture;
    text.insert(text.find("POSI"), inserted);  // line 9
    const fs::path path = WriteFixture("ratslam_ipin_garbage.txt", text);
    StatusOr<Dataset> strict = ReadIpinLog(path.string(), {});
    ASSERT_FALSE(strict.ok()) << expected;
    EXPECT_NE(strict.status().message().find("ratslam_ipin_garbage.txt:9: not a sensor line"),
              std::string::npos)
        << strict.status().message();
    EXPECT_NE(strict.status().message().find(expected), std::string::npos)
        << strict.status().message();
    PhoneLogReport report;
    StatusOr<Dataset> d = ReadLeniently(path, &report);
    ASSERT_TRUE(d.ok()) << d.status().message();
    EXPECT_GE(report.skipped_malformed, 1u);
    EXPECT_EQ(d->wifi.size(), 2u);
    EXPECT_EQ(d->ground_truth.size(), 2u);
  }
  // A log cut in the middle of its last line is an error too (its fields are missing).
  std::string cut = kFixture;
  cut.resize(cut.size() - 20);
  const fs::path path = WriteFixture("ratslam_ipin_cut.txt", cut);
  EXPECT_FALSE(ReadIpinLog(path.string(), {}).ok());
}

// Nonsense that once loaded silently: a latitude of 4000 degrees (y = 4.4e8 m), a floor of 1e300
// (read as floor 0, and an undefined cast), a negative time, a latitude of 1e308.
TEST(IpinLogTest, OutOfRangeValuesNameTheFieldAndLine) {
  const std::pair<const char*, const char*> cases[] = {
      {"POSI;5.0;3;4000.0;11.11;0;100\n", "Latitude is out of range [-90, 90]"},
      {"POSI;5.0;3;1e308;11.11;0;100\n", "Latitude is out of range"},
      {"POSI;5.0;3;49.46;11.11;1e300;100\n", "floor is out of range [-1000, 1000]"},
      {"POSI;5.0;3;49.46;11.11;1.5;100\n", "floor is not a whole number"},
      {"WIFI;-5.0;105.0;net;aa:bb;2437;-60\n", "AppTimestamp(s) is out of range"},
      {"ACCE;5.1;105.1;0.1;0.2;1e9;3\n", "Acc_Z is out of range"},
      {"PRES;5.2;105.2;9768.7;3\n", "Pressure(mbar) is out of range [100, 1100]"},
      {"PRES;5.2;105.2;nan;3\n", "Pressure(mbar) is not a number"},
      {"PRES;5.2;105.2\n", "missing field Pressure(mbar)"},
      // A field of a lone carriage return (the fuzzer: once a pointer past the string's end).
      {"PRES;5.2;105.2;\r;3\n", "Pressure(mbar) is not a number"},
      {"PRES;5.2;105.2; \t;3\n", "Pressure(mbar) is not a number"},
  };
  for (const auto& [line, expected] : cases) {
    const fs::path path = WriteFixture("ratslam_ipin_range.txt", std::string(kFixture) + line);
    StatusOr<Dataset> d = ReadIpinLog(path.string(), {});
    ASSERT_FALSE(d.ok()) << line;
    EXPECT_NE(d.status().message().find("ratslam_ipin_range.txt:11: "), std::string::npos)
        << d.status().message();
    EXPECT_NE(d.status().message().find(expected), std::string::npos) << d.status().message();
  }
  EXPECT_NE(ReadIpinLog("/dev/zero", {}).status().message().find("not a regular file"),
            std::string::npos);
}

TEST(IpinLogTest, BarometerReadingsAreKeptInTimeOrder) {
  const fs::path path = WriteFixture("ratslam_ipin_pres.txt", std::string(kFixture) +
                                                                  "PRES;2.0;102.0;976.8628;3\n"
                                                                  "PRES;1.5;101.5;976.8699;3\n");
  StatusOr<PhoneLog> log = ParseIpinLog(path.string(), {});
  ASSERT_TRUE(log.ok()) << log.status().message();
  ASSERT_EQ(log->streams.pressure.size(), 2u);
  EXPECT_EQ(log->streams.pressure[0].time_s, 1.5);
  EXPECT_EQ(log->streams.pressure[0].pressure_hpa, 976.8699);
  EXPECT_EQ(log->streams.pressure[1].pressure_hpa, 976.8628);
}

TEST(IpinLogTest, StepsBecomeOdometryRows) {
  const std::vector<sensors::Step> steps = {{1.0, 0.7, 0.0}, {1.5, 0.8, 0.5}};
  const std::vector<OdometryRow> rows = StepsToOdometry(steps, 0.0);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_DOUBLE_EQ(rows[1].forward_speed_m_per_s * 1.0, 0.7);
  EXPECT_DOUBLE_EQ(rows[2].forward_speed_m_per_s * 0.5, 0.8);
  EXPECT_DOUBLE_EQ(rows[2].turn_rate_rad_per_s * 0.5, 0.5);
}

// On a real log: the walk's path length from dead reckoning is close to the ground truth's.
TEST(IpinLogTest, RealLogDeadReckoningDistanceMatchesGroundTruth) {
  const fs::path log = fs::path(ratslam::test_paths::SharedDataDir()) / "ipin2023-t3" /
                       "IPIN2023_T3_TrainingTrial01_repetition01.txt";
  if (!fs::exists(log)) GTEST_SKIP() << "missing " << log;
  PhoneLogReport report;
  StatusOr<Dataset> d = ReadIpinLog(log.string(), {}, &report);
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_EQ(d->ground_truth.size(), 14u);
  EXPECT_GT(d->wifi.size(), 40u);
  double truth = 0.0, walked = 0.0;
  for (size_t i = 1; i < d->ground_truth.size(); ++i) {
    truth += std::hypot(d->ground_truth[i].x_m - d->ground_truth[i - 1].x_m,
                        d->ground_truth[i].y_m - d->ground_truth[i - 1].y_m);
  }
  for (size_t i = 1; i < d->odometry.size(); ++i) {
    const double t = d->odometry[i].time_s;
    if (t < d->ground_truth.front().time_s || t > d->ground_truth.back().time_s) continue;
    walked += d->odometry[i].forward_speed_m_per_s * (t - d->odometry[i - 1].time_s);
  }
  EXPECT_NEAR(walked / truth, 1.0, 0.25) << "walked " << walked << " m, truth " << truth << " m";
}

// Parsing runs no dead reckoning: one parsed log becomes data sets under two PDR settings
// without being read again, and the parse keeps every raw sample.
TEST(IpinLogTest, ParsedLogIsReckonedAfterwardsUnderAnySettings) {
  const fs::path log = fs::path(ratslam::test_paths::SharedDataDir()) / "ipin2023-t3" /
                       "IPIN2023_T3_TrainingTrial01_repetition01.txt";
  if (!fs::exists(log)) GTEST_SKIP() << "missing " << log;
  StatusOr<PhoneLog> parsed = ParseIpinLog(log.string(), {});
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  EXPECT_GT(parsed->streams.accelerometer.size(), 1000u);
  EXPECT_GT(parsed->streams.headings.size(), 1000u);
  PhoneLogOptions fixed;
  fixed.pdr.fixed_step_length_m = 0.5;
  PhoneLogReport weinberg_report, fixed_report;
  StatusOr<Dataset> weinberg = PhoneLogToDataset(*parsed, {}, &weinberg_report);
  StatusOr<Dataset> constant = PhoneLogToDataset(*parsed, fixed, &fixed_report);
  ASSERT_TRUE(weinberg.ok() && constant.ok());
  // The same steps are detected; with a fixed length the distance is exactly 0.5 m per step.
  EXPECT_EQ(weinberg_report.steps, fixed_report.steps);
  ASSERT_GT(fixed_report.steps, 20u);
  double walked = 0.0;
  for (size_t i = 1; i < constant->odometry.size(); ++i) {
    walked += constant->odometry[i].forward_speed_m_per_s *
              (constant->odometry[i].time_s - constant->odometry[i - 1].time_s);
  }
  EXPECT_NEAR(walked, 0.5 * static_cast<double>(constant->odometry.size() - 1), 1e-9);
  // The one-call reader is exactly the two steps.
  StatusOr<Dataset> direct = ReadIpinLog(log.string(), {});
  ASSERT_TRUE(direct.ok());
  ASSERT_EQ(direct->odometry.size(), weinberg->odometry.size());
  for (size_t i = 0; i < direct->odometry.size(); ++i) {
    EXPECT_EQ(direct->odometry[i].forward_speed_m_per_s,
              weinberg->odometry[i].forward_speed_m_per_s);
  }
}

TEST(IpinLogTest, BadDeadReckoningOptionsFailBeforeTheFileIsRead) {
  PhoneLogOptions bad;
  bad.pdr.baseline_s = 0.0;
  const std::string message = ReadIpinLog("/nonexistent.txt", bad).status().message();
  EXPECT_EQ(message.rfind("pdr.", 0), 0u) << message;
  bad = PhoneLogOptions();
  bad.compass_rate_hz = 0.0;
  EXPECT_EQ(ReadIpinLog("/nonexistent.txt", bad).status().message(),
            "compass_rate_hz: must be positive");
}

}  // namespace
}  // namespace ratslam::dataset
