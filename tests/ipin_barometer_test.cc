// Floors from the barometer on real phone logs (IPIN 2023 Track 3, ../shared/data/ipin2023-t3/):
// routes 01-03 and 21-23 stay on one floor (0 and -2), route 51 walks floors 0, -1 and -2 twice
// (sensors/barometer.h; no ground truth or map is used by the estimate).
//
// Why these thresholds: on the single-floor routes any floor change is a mistake, so none is
// allowed in 24 walks. On route 51 the ground-truth points are labelled with floors; the
// estimate (relative to the first level, plus the first point's floor) must agree with them far
// more often than the baseline that never leaves the start floor (which is right at the points
// on floor 0 only). A point passed while still on the stairs is labelled with the floor being
// reached, and the tracker changes floor only after a dwell there, so a few points lag.
#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>
#include <string>

#include "dataset/ipin_log.h"
#include "sensors/barometer.h"
#include "tests/test_paths.h"

namespace ratslam {
namespace {
namespace fs = std::filesystem;

struct FloorScore {
  size_t points = 0, right = 0, start_floor_right = 0, changes = 0, readings = 0;
};

FloorScore ScoreLog(const fs::path& path) {
  FloorScore score;
  StatusOr<dataset::PhoneLog> log =
      dataset::ParseIpinLog(path.string(), dataset::PhoneLogOptions());
  EXPECT_TRUE(log.ok()) << log.status().message();
  if (!log.ok() || log->streams.ground_truth.empty()) return score;
  sensors::BarometricFloorTracker tracker;
  const auto& truth = log->streams.ground_truth;
  const int start = truth.front().floor;
  size_t next = 0;
  for (const PressureSample& p : log->streams.pressure) {
    StatusOr<sensors::FloorEstimate> e = tracker.Add(p);
    EXPECT_TRUE(e.ok()) << e.status().message();
    if (!e.ok()) return score;
    ++score.readings;
    while (next < truth.size() && truth[next].time_s <= p.time_s) {
      ++score.points;
      score.right += start + e->floor == truth[next].floor;
      score.start_floor_right += start == truth[next].floor;
      ++next;
    }
  }
  score.changes = tracker.floor_changes();
  return score;
}

TEST(IpinBarometerTest, FloorsFromPressureOnTheTrainingLogs) {
  const fs::path data = fs::path(ratslam::test_paths::SharedDataDir()) / "ipin2023-t3";
  const fs::path route51 = data / "IPIN2023_T3_TrainingTrial51_repetition02.txt";
  if (!fs::exists(route51)) GTEST_SKIP() << "missing " << route51;
  size_t single_floor_logs = 0, single_floor_changes = 0;
  for (const char* route : {"01", "02", "03", "21", "22", "23"}) {
    for (const char* rep : {"01", "02", "03", "04"}) {
      const fs::path log =
          data / (std::string("IPIN2023_T3_TrainingTrial") + route + "_repetition" + rep + ".txt");
      if (!fs::exists(log)) continue;
      const FloorScore s = ScoreLog(log);
      ASSERT_GT(s.readings, 100u) << log << ": no barometer readings";
      EXPECT_EQ(s.right, s.points) << log;
      ++single_floor_logs;
      single_floor_changes += s.changes;
      std::cout << "route " << route << " rep " << rep << ": " << s.changes << " floor changes, "
                << s.right << "/" << s.points << " points right\n";
    }
  }
  EXPECT_EQ(single_floor_changes, 0u) << "in " << single_floor_logs << " single-floor walks";
  const FloorScore s = ScoreLog(route51);
  std::cout << "route 51: " << s.changes << " floor changes, " << s.right << "/" << s.points
            << " points on the right floor (start floor throughout: " << s.start_floor_right
            << ")\n";
  // The walk changes floor 8 times (0 -1 -2 -1 0 -1 -2 -1 0); a pause on a landing or noise
  // must not add many.
  EXPECT_GE(s.changes, 8u);
  EXPECT_LE(s.changes, 10u);
  EXPECT_GE(s.right, s.start_floor_right + (s.points - s.start_floor_right) * 2 / 3);
  EXPECT_GE(s.right * 4, s.points * 3);
}

}  // namespace
}  // namespace ratslam
