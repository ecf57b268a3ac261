#include "session/evaluation_baselines.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>

#include "common/random.h"

namespace ratslam::session {
namespace {

using fabmap::Estimate;
using fabmap::EvaluationNode;

EvaluationNode Node(double x, double y, int floor, std::vector<WifiReading> scan) {
  EvaluationNode n;
  n.x_m = x;
  n.y_m = y;
  n.floor = floor;
  n.wifi = std::move(scan);
  return n;
}

// Known answer: the query equals map scan 1 and is 1 dB from scans 0 and 2 on one AP; scan 3 is
// far. The three nearest are 1 (d = 0, weight 1 / 1e-3), 0 and 2 (d = 1): the estimate is their
// weighted mean, almost exactly scan 1's position.
TEST(EvaluationBaselinesTest, KnnWeightsTheNearestThreeByInverseDistance) {
  const std::vector<EvaluationNode> map = {
      Node(0, 0, 0, {{"a", -50}, {"b", -61}}), Node(10, 0, 0, {{"a", -50}, {"b", -60}}),
      Node(20, 0, 0, {{"a", -51}, {"b", -60}}), Node(90, 0, 0, {{"c", -40}})};
  const std::vector<EvaluationNode> queries = {Node(10, 0, 0, {{"a", -50}, {"b", -60}})};
  const std::vector<Estimate> e = KnnEstimates(map, queries);
  ASSERT_TRUE(e[0].located);
  const double w = 1e3;  // 1 / max(0, 1e-3)
  EXPECT_NEAR(e[0].x_m, (w * 10 + 1 * 0 + 1 * 20) / (w + 2), 1e-9);
  EXPECT_EQ(e[0].floor, 0);
}

// Floors vote by weight: two weak neighbours on floor 1 lose to one strong one on floor 0, and
// the position comes only from the winning floor's neighbours.
TEST(EvaluationBaselinesTest, KnnFloorIsAWeightedVoteAndPositionUsesThatFloorOnly) {
  const std::vector<EvaluationNode> map = {
      Node(5, 5, 0, {{"a", -50}}), Node(50, 0, 1, {{"a", -54}}), Node(60, 0, 1, {{"a", -46}})};
  const std::vector<Estimate> e = KnnEstimates(map, {Node(0, 0, 0, {{"a", -50.5}})});
  ASSERT_TRUE(e[0].located);
  EXPECT_EQ(e[0].floor, 0);  // 1 / 0.5 = 2 against 1 / 3.5 + 1 / 4.5 = 0.51
  EXPECT_DOUBLE_EQ(e[0].x_m, 5.0);
  EXPECT_DOUBLE_EQ(e[0].y_m, 5.0);
}

// The inverted-index distance equals a dense Euclidean distance over every AP (not heard =
// kKnnNotHeardDbm), computed here independently, on random scans with unknown and repeated APs.
TEST(EvaluationBaselinesTest, KnnMatchesADenseOracle) {
  Random random(11);
  const auto scan = [&](int aps) {
    std::vector<WifiReading> s;
    for (int i = 0; i < aps; ++i) {
      s.push_back({"ap" + std::to_string(static_cast<int>(random.Uniform(0, 30))),
                   random.Uniform(-95, -30)});
    }
    return s;
  };
  std::vector<EvaluationNode> map, queries;
  for (int i = 0; i < 60; ++i) map.push_back(Node(i, 2.0 * i, i % 3, scan(6)));
  for (int i = 0; i < 40; ++i) {
    auto s = scan(5);
    s.push_back({"unknown" + std::to_string(i), -70});  // an AP the map never heard
    queries.push_back(Node(0, 0, 0, s));
  }
  const auto dense = [](const std::vector<WifiReading>& s) {
    std::map<std::string, std::pair<double, int>> sum;
    for (const auto& r : s) sum[r.bssid].first += r.rssi_dbm, sum[r.bssid].second++;
    std::map<std::string, double> v;
    for (const auto& [b, x] : sum) v[b] = x.first / x.second;
    return v;
  };
  const std::vector<Estimate> got = KnnEstimates(map, queries, 3);
  for (size_t q = 0; q < queries.size(); ++q) {
    const auto qv = dense(*queries[q].wifi);
    std::vector<std::pair<double, size_t>> d;
    for (size_t m = 0; m < map.size(); ++m) {
      const auto mv = dense(*map[m].wifi);
      std::set<std::string> all;
      for (const auto& [b, x] : qv) all.insert(b);
      for (const auto& [b, x] : mv) all.insert(b);
      double d2 = 0.0;
      for (const std::string& b : all) {
        const double a = qv.count(b) ? qv.at(b) : kKnnNotHeardDbm;
        const double c = mv.count(b) ? mv.at(b) : kKnnNotHeardDbm;
        d2 += (a - c) * (a - c);
      }
      d.push_back({std::sqrt(d2), m});
    }
    std::sort(d.begin(), d.end());
    std::map<int, double> votes;
    for (int k = 0; k < 3; ++k) votes[map[d[k].second].floor] += 1.0 / d[k].first;
    int floor = map[d[0].second].floor;
    for (const auto& [f, w] : votes) {
      if (w > votes[floor]) floor = f;
    }
    double x = 0.0, total = 0.0;
    for (int k = 0; k < 3; ++k) {
      if (map[d[k].second].floor != floor) continue;
      x += map[d[k].second].x_m / d[k].first;
      total += 1.0 / d[k].first;
    }
    ASSERT_TRUE(got[q].located);
    EXPECT_EQ(got[q].floor, floor) << q;
    EXPECT_NEAR(got[q].x_m, x / total, 1e-6) << q;
  }
}

TEST(EvaluationBaselinesTest, QueriesWithoutScansAreRejectedAndFingerprintHonoursTheThreshold) {
  std::vector<EvaluationNode> map = {Node(0, 0, 0, {{"a", -40}, {"b", -45}}),
                                     Node(30, 0, 0, {{"c", -40}, {"d", -45}})};
  EvaluationNode silent = Node(1, 1, 0, {});
  silent.wifi.reset();
  const std::vector<EvaluationNode> queries = {
      Node(1, 0, 0, {{"a", -41}, {"b", -44}}),  // close to map scan 0
      Node(2, 0, 0, {{"e", -40}}),              // shares no AP: rejected
      silent};
  const std::vector<Estimate> knn = KnnEstimates(map, queries);
  ASSERT_TRUE(knn[0].located);
  EXPECT_LT(knn[0].x_m, 1.0);    // weights ~1/1.4 against ~1/135 for the scan at 30 m
  EXPECT_TRUE(knn[1].located);   // k-NN never rejects a query that has a scan
  EXPECT_FALSE(knn[2].located);  // no scan: rejected
  const std::vector<Estimate> fp =
      FingerprintEstimates(map, queries, sensors::WifiMatcherOptions{});
  ASSERT_TRUE(fp[0].located);
  EXPECT_EQ(fp[0].x_m, 0.0);
  EXPECT_FALSE(fp[1].located);
  EXPECT_FALSE(fp[2].located);
  sensors::WifiMatcherOptions strict;
  strict.match_threshold = 1.0;  // only an identical scan could reach it
  EXPECT_FALSE(FingerprintEstimates(map, queries, strict)[0].located);
}

}  // namespace
}  // namespace ratslam::session
