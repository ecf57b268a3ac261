#include "session/evaluation_nodes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "tests/test_paths.h"

namespace ratslam::session {
namespace {

TEST(EvaluationNodesTest, LoadsAnImageFolderWithFloors) {
  const std::string path =
      std::string(ratslam::test_paths::SharedDataDir()) + "/multifloor-corridors";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path;
  fabmap::EvaluationOptions options;
  options.frame_spacing_m = 0.5;
  const auto nodes = LoadEvaluationNodes(path, true, true, options, {});
  ASSERT_TRUE(nodes.ok()) << nodes.status().message();
  ASSERT_EQ(nodes->size(), 1500u);
  EXPECT_EQ(nodes->front().floor, 1);
  EXPECT_EQ(nodes->back().floor, 3);
  EXPECT_DOUBLE_EQ((*nodes)[1].x_m, 0.5);
  EXPECT_FALSE(nodes->front().wifi.has_value());
}

TEST(EvaluationNodesTest, BadPathsAndOptionsAreErrors) {
  fabmap::EvaluationOptions options;
  const auto missing = LoadEvaluationNodes("/no/such/place", true, false, options, {});
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("/no/such/place"), std::string::npos);
  options.map_fraction = 1.5;
  EXPECT_FALSE(
      LoadEvaluationNodes(ratslam::test_paths::SourceDir(), true, false, options, {}).ok());
}

// Map scans along a corridor; two query sessions walk it, one with a phone 10 dB lower and one
// with the map's phone. Each session's offset is estimated from its own scans in time order (the
// nodes are given out of order): the lower phone's first nine scans stay as they were, the tenth
// (whose estimate is the tenth) and later ones lose the offset known at their time (about
// -10 dB); the map's phone loses nothing.
TEST(RemoveQueryRssiOffsetsTest, RecoversEachSessionsPlantedOffset) {
  auto scan = [](double x, double shift_db, int t) {
    std::vector<WifiReading> readings;
    for (int k = 0; k < 10; ++k) {
      const double d = std::abs(x - 8.0 * k) + 1.0;
      // +-1 dB of deterministic noise per AP and time.
      const double rssi = -30.0 - 25.0 * std::log10(d) + std::sin(7.0 * t + k) + shift_db;
      readings.push_back({"ap" + std::to_string(k), rssi});
    }
    return readings;
  };
  std::vector<fabmap::EvaluationNode> map, queries;
  for (int i = 0; i < 40; ++i) {
    fabmap::EvaluationNode n;
    n.x_m = 2.0 * i;
    n.wifi = scan(n.x_m, 0.0, i);
    map.push_back(n);
  }
  for (int i = 39; i >= 0; --i) {  // reverse time order in the vector
    for (int session : {7, 3}) {
      fabmap::EvaluationNode n;
      n.x_m = 2.0 * i + 1.0;
      n.time_s = i;
      n.session = session;
      n.wifi = scan(n.x_m, session == 7 ? -10.0 : 0.0, 100 + i);
      queries.push_back(n);
    }
  }
  const std::vector<fabmap::EvaluationNode> before = queries;
  const std::vector<SessionRssiOffset> offsets = RemoveQueryRssiOffsets(map, &queries, 5, 10);
  ASSERT_EQ(offsets.size(), 2u);
  EXPECT_EQ(offsets[0].session, 7);  // first appearance
  EXPECT_NEAR(offsets[0].offset_db, -10.0, 1.0);
  EXPECT_EQ(offsets[1].session, 3);
  EXPECT_NEAR(offsets[1].offset_db, 0.0, 1.0);
  for (size_t i = 0; i < queries.size(); ++i) {
    const double shift = queries[i].wifi->front().rssi_dbm - before[i].wifi->front().rssi_dbm;
    if (queries[i].session == 7 && queries[i].time_s < 8.5) {
      EXPECT_EQ(shift, 0.0) << "scan " << queries[i].time_s << " came before the tenth estimate";
    } else if (queries[i].session == 7) {  // the offset known at that scan, online
      EXPECT_NEAR(shift, 10.0, 1.0);
    } else {
      EXPECT_NEAR(shift, 0.0, 1.0);
    }
    // Every reading of a scan moves by the same amount.
    for (size_t k = 0; k < queries[i].wifi->size(); ++k) {
      EXPECT_NEAR((*queries[i].wifi)[k].rssi_dbm - (*before[i].wifi)[k].rssi_dbm, shift, 1e-9);
    }
  }
}

}  // namespace
}  // namespace ratslam::session
