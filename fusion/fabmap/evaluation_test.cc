#include "fusion/fabmap/evaluation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>

namespace ratslam::fabmap {
namespace {

EvaluationNode At(double x, double y, int floor) {
  EvaluationNode n;
  n.x_m = x;
  n.y_m = y;
  n.floor = floor;
  return n;
}

TEST(EvaluationTest, MetricsOnAHandBuiltCase) {
  const std::vector<EvaluationNode> map = {At(0, 0, 0), At(10, 0, 0), At(0, 0, 1)};
  const std::vector<EvaluationNode> queries = {At(1, 0, 0), At(4, 0, 0), At(0, 3, 0), At(50, 0, 0),
                                               At(0, 0, 0)};
  // errors: |(0,0)-(1,0)| = 1; |(10,0)-(4,0)| = 6; map 2 is floor 1: infinite; rejected;
  // |(0,0)-(0,0)| = 0.
  const std::vector<int64_t> matches = {0, 1, 2, -1, 0};
  const EvaluationMetrics m = ComputeMetrics(map, queries, matches, {2, 5, 10, 20});
  EXPECT_EQ(m.queries, 5u);
  EXPECT_DOUBLE_EQ(m.correct_within[0], 2.0 / 5);  // errors 1 and 0
  EXPECT_DOUBLE_EQ(m.correct_within[1], 2.0 / 5);
  EXPECT_DOUBLE_EQ(m.correct_within[2], 3.0 / 5);  // plus 6
  EXPECT_DOUBLE_EQ(m.correct_within[3], 3.0 / 5);
  EXPECT_DOUBLE_EQ(m.misplaced_beyond[0], 2.0 / 5);  // 6 and the floor mistake
  EXPECT_DOUBLE_EQ(m.misplaced_beyond[2], 1.0 / 5);  // the floor mistake only
  EXPECT_DOUBLE_EQ(m.misplaced_beyond[3], 1.0 / 5);
  EXPECT_DOUBLE_EQ(m.rejection_rate, 1.0 / 5);
  EXPECT_DOUBLE_EQ(m.floor_mistake_rate, 1.0 / 5);
  // Correct + misplaced + rejected = 1 at every d.
  for (size_t k = 0; k < 4; ++k) {
    EXPECT_DOUBLE_EQ(m.correct_within[k] + m.misplaced_beyond[k] + m.rejection_rate, 1.0);
  }
  EXPECT_TRUE(std::isinf(m.errors_m[2]));
  EXPECT_TRUE(std::isnan(m.errors_m[3]));
}

// Estimates off the map's places (k-NN averages) count by their own position.
TEST(EvaluationTest, MetricsOfPositionEstimates) {
  const std::vector<EvaluationNode> queries = {At(0, 0, 0), At(0, 0, 0), At(0, 0, 1)};
  const std::vector<Estimate> estimates = {{true, 3, 4, 0}, {}, {true, 0, 0, 0}};
  const EvaluationMetrics m = ComputeMetrics(queries, estimates, {2, 5});
  EXPECT_DOUBLE_EQ(m.errors_m[0], 5.0);
  EXPECT_DOUBLE_EQ(m.correct_within[0], 0.0);
  EXPECT_DOUBLE_EQ(m.correct_within[1], 1.0 / 3);  // 5 <= 5
  EXPECT_DOUBLE_EQ(m.rejection_rate, 1.0 / 3);
  EXPECT_DOUBLE_EQ(m.floor_mistake_rate, 1.0 / 3);
}

// The reachable share: a map place on the query's floor within d, brute force on a grid.
TEST(EvaluationTest, NearestPlaceWithinAgreesWithBruteForce) {
  std::vector<EvaluationNode> map, queries;
  for (int i = 0; i < 30; ++i) map.push_back(At((i * 7) % 23, (i * 5) % 17, i % 2));
  for (int i = 0; i < 50; ++i) queries.push_back(At((i * 3) % 29 - 2.5, (i * 11) % 19, i % 3));
  const std::vector<double> d = {1, 2, 5, 10};
  const std::vector<double> got = NearestPlaceWithin(map, queries, d);
  for (size_t k = 0; k < d.size(); ++k) {
    int near = 0;
    for (const auto& q : queries) {
      bool any = false;
      for (const auto& p : map) {
        any |= p.floor == q.floor && std::hypot(p.x_m - q.x_m, p.y_m - q.y_m) <= d[k];
      }
      near += any;
    }
    EXPECT_DOUBLE_EQ(got[k], near / 50.0) << d[k];
  }
  EXPECT_LT(got[0], got[3]);  // the case is not trivial
  EXPECT_LT(got[3], 1.0);     // floor 2 has no map place
}

// Floors 0 and 1 hold map places, floor 2 none: a third of these queries is out of reach.
TEST(EvaluationTest, FloorClassificationOnAHandBuiltCase) {
  const std::vector<EvaluationNode> map = {At(0, 0, 0), At(5, 0, 1), At(9, 9, 1)};
  const std::vector<EvaluationNode> queries = {At(1, 1, 0), At(2, 2, 1), At(3, 3, 2),
                                               At(4, 4, 0), At(5, 5, 1), At(6, 6, 2)};
  EXPECT_DOUBLE_EQ(ShareOnMappedFloors(map, queries), 4.0 / 6.0);
  EXPECT_DOUBLE_EQ(ShareOnMappedFloors(map, {}), 0.0);
  EXPECT_DOUBLE_EQ(ShareOnMappedFloors({}, queries), 0.0);
  // Right, wrong, wrong (an unmapped floor), no answer, right, right (a floor a map place
  // cannot name, but a classifier may).
  const std::vector<std::optional<int>> floors = {0, 0, 1, std::nullopt, 1, 2};
  EXPECT_DOUBLE_EQ(FloorAccuracy(queries, floors), 3.0 / 6.0);
  EXPECT_DOUBLE_EQ(FloorAccuracy(queries, {0, 1}), 0.0);  // sizes disagree
}

TEST(EvaluationTest, InterleavedSplitKeepsTheFraction) {
  const auto split = InterleavedSplit(10, 0.4);
  int in_map = 0;
  for (bool b : split) in_map += b;
  EXPECT_EQ(in_map, 4);
  // No run of more than 2 queries between map items (1 / 0.4 = 2.5).
  int run = 0;
  for (bool b : split) {
    run = b ? 0 : run + 1;
    EXPECT_LE(run, 2);
  }
}

// Split by session keeps whole sessions together; first_session maps with the first only.
TEST(EvaluationTest, SplitBySessionAndFirstSession) {
  std::vector<EvaluationNode> nodes;
  for (int session = 0; session < 5; ++session) {
    for (int i = 0; i < 3; ++i) {
      nodes.push_back(At(i, session, 0));
      nodes.back().session = session;
    }
  }
  EvaluationOptions options;
  options.split = SplitUnit::kSession;
  options.map_fraction = 0.4;  // sessions 2 and 4: floor((i+1) 0.4) > floor(i 0.4)
  const SplitNodes by_session = SplitEvaluationNodes(nodes, options);
  ASSERT_EQ(by_session.map.size(), 6u);
  EXPECT_EQ(by_session.map.front().session, 2);
  EXPECT_EQ(by_session.map.back().session, 4);
  EXPECT_EQ(by_session.queries.size(), 9u);
  options.split = SplitUnit::kFirstSession;
  const SplitNodes first = SplitEvaluationNodes(nodes, options);
  ASSERT_EQ(first.map.size(), 3u);
  for (const auto& n : first.map) EXPECT_EQ(n.session, 0);
  EXPECT_EQ(first.queries.size(), 12u);
  options.split = SplitUnit::kNode;
  const SplitNodes by_node = SplitEvaluationNodes(nodes, options);
  EXPECT_EQ(by_node.map.size(), 6u);  // 15 nodes at 0.4
  EXPECT_EQ(by_node.map.size() + by_node.queries.size(), nodes.size());
  EXPECT_FALSE(SplitUnitFromString("nodes").ok());
}

// Sessions that take turns in time (UJIIndoorLoc's users and phones did) stay whole: the split
// is over session ids in the order of their first node, not over runs of nodes.
TEST(EvaluationTest, SplitBySessionKeepsInterleavedSessionsWhole) {
  std::vector<EvaluationNode> nodes;
  for (int session : {7, 3, 7, 3, 9, 7, 5, 3, 9, 5, 8}) {  // first seen: 7, 3, 9, 5, 8
    nodes.push_back(At(0, 0, 0));
    nodes.back().session = session;
  }
  EvaluationOptions options;
  options.split = SplitUnit::kSession;
  options.map_fraction = 0.4;  // the 3rd and 5th of five (indices 2 and 4): sessions 9 and 8
  const SplitNodes split = SplitEvaluationNodes(nodes, options);
  ASSERT_EQ(split.map.size(), 3u);  // 9 twice, 8 once
  for (const auto& n : split.map) EXPECT_TRUE(n.session == 9 || n.session == 8) << n.session;
  ASSERT_EQ(split.queries.size(), 8u);
  for (const auto& n : split.queries) EXPECT_TRUE(n.session != 9 && n.session != 8) << n.session;
  options.split = SplitUnit::kFirstSession;  // session 7, all three of its nodes
  const SplitNodes first = SplitEvaluationNodes(nodes, options);
  ASSERT_EQ(first.map.size(), 3u);
  for (const auto& n : first.map) EXPECT_EQ(n.session, 7);
}

TEST(EvaluationTest, SplitByPositionKeepsEveryPositionOnOneSide) {
  // Positions (floor, x, y) first seen in the order A, B, C, D, E; A and C repeat, and (1, 0, 0)
  // differs from A = (0, 0, 0) by its floor only.
  std::vector<EvaluationNode> nodes = {At(0, 0, 0), At(5, 0, 0), At(0, 0, 0), At(0, 5, 0),
                                       At(0, 5, 0), At(0, 0, 1), At(9, 9, 2), At(5, 0, 0)};
  EvaluationOptions options;
  options.split = SplitUnit::kPosition;
  options.map_fraction = 0.4;  // the 3rd and 5th of five positions: (0, 5, 0) and (9, 9, 2)
  const SplitNodes split = SplitEvaluationNodes(nodes, options);
  ASSERT_EQ(split.map.size(), 3u);
  for (const auto& n : split.map) {
    EXPECT_TRUE((n.x_m == 0 && n.y_m == 5 && n.floor == 0) || (n.x_m == 9 && n.floor == 2));
  }
  ASSERT_EQ(split.queries.size(), 5u);
  for (const auto& q : split.queries) {  // no query stands where a map node does
    for (const auto& m : split.map) {
      EXPECT_FALSE(q.x_m == m.x_m && q.y_m == m.y_m && q.floor == m.floor);
    }
  }
}

TEST(PosteriorEstimateTest, OnePlaceIsTheArgMax) {
  const std::vector<EvaluationNode> map = {At(0, 0, 0), At(10, 0, 0), At(20, 0, 1)};
  const Estimate e = PosteriorEstimate(map, {0.2, 0.7, 0.1}, 1, 1.0);
  ASSERT_TRUE(e.located);
  EXPECT_EQ(e.x_m, 10.0);
  EXPECT_EQ(e.y_m, 0.0);
  EXPECT_EQ(e.floor, 0);
}

TEST(PosteriorEstimateTest, WeightsAreTemperedPosteriorsOnTheWinningFloor) {
  // Posteriors 1 and e^-10 at x = 0 and 10; temperature 10 makes the weights 1 and e^-1. The
  // third place (floor 1) is below both and loses the floor vote.
  const std::vector<EvaluationNode> map = {At(0, 0, 0), At(10, 4, 0), At(50, 50, 1)};
  const std::vector<double> p = {1.0 / (1 + std::exp(-10.0) + 1e-9),
                                 std::exp(-10.0) / (1 + std::exp(-10.0) + 1e-9), 1e-9};
  const Estimate e = PosteriorEstimate(map, p, 3, 10.0);
  ASSERT_TRUE(e.located);
  EXPECT_EQ(e.floor, 0);
  const double w = std::exp(-1.0);
  EXPECT_NEAR(e.x_m, 10 * w / (1 + w), 1e-9);
  EXPECT_NEAR(e.y_m, 4 * w / (1 + w), 1e-9);
  // Temperature 1: the runner-up weighs e^-10 and the answer is nearly the best place.
  const double v = std::exp(-10.0);
  EXPECT_NEAR(PosteriorEstimate(map, p, 3, 1.0).x_m, 10 * v / (1 + v), 1e-12);
  // Equal posteriors: the midpoint.
  const Estimate mid = PosteriorEstimate(map, {0.4, 0.4, 0.2}, 2, 1.0);
  EXPECT_DOUBLE_EQ(mid.x_m, 5.0);
  EXPECT_DOUBLE_EQ(mid.y_m, 2.0);
}

TEST(PosteriorEstimateTest, BuildingIsVotedBeforeTheFloor) {
  // Building 1 holds the best place (0.4) but building 0's two places weigh 0.6 together; in
  // building 0, floor 2 (0.35) beats floor 1 (0.25). The answer is floor 2's place alone, though
  // floor 1 of building 1 would have won a vote of floors alone.
  std::vector<EvaluationNode> map = {At(0, 0, 1), At(10, 0, 2), At(30, 30, 101)};
  map[2].building = 1;
  const Estimate e = PosteriorEstimate(map, {0.25, 0.35, 0.4}, 3, 1.0);
  ASSERT_TRUE(e.located);
  EXPECT_EQ(e.floor, 2);
  EXPECT_EQ(e.x_m, 10.0);
  // Only the most probable places vote: with two, building 1 (0.4) beats building 0 (0.35).
  const Estimate two = PosteriorEstimate(map, {0.25, 0.35, 0.4}, 2, 1.0);
  EXPECT_EQ(two.floor, 101);
  EXPECT_EQ(two.x_m, 30.0);
}

TEST(PosteriorEstimateTest, NoPositivePosteriorIsNoAnswer) {
  const std::vector<EvaluationNode> map = {At(0, 0, 0), At(10, 0, 0)};
  EXPECT_FALSE(PosteriorEstimate(map, {0.0, 0.0}, 5, 1.0).located);
  EXPECT_FALSE(PosteriorEstimate(map, {}, 5, 1.0).located);
  EXPECT_FALSE(PosteriorEstimate(map, {0.5, 0.5}, 0, 1.0).located);
  // A posterior past the map's end takes no part; a NaN is not positive.
  const Estimate e = PosteriorEstimate(map, {0.0, std::nan(""), 0.9}, 5, 1.0);
  EXPECT_FALSE(e.located);
  const Estimate f = PosteriorEstimate(map, {0.3, std::nan(""), 0.9}, 5, 1.0);
  ASSERT_TRUE(f.located);
  EXPECT_EQ(f.x_m, 0.0);
}

// Hand-worked: five queries, best-place posteriors 0.9, 0.8, 0.8, 0.3 and none; errors 1, 30, 4,
// 3 m; the last query has no map place on its floor. Equal posteriors are accepted together.
TEST(PrecisionRecallTest, HandWorkedCurve) {
  const double inf = std::numeric_limits<double>::infinity();
  const auto curve = PrecisionRecallCurve({0.9, 0.8, 0.8, 0.3, std::nan("")}, {1, 30, 4, 3, inf},
                                          {0.5, 1, 2, 1, inf}, {2, 5});
  ASSERT_EQ(curve.size(), 3u);
  const size_t accepted[3] = {1, 3, 4};
  const double threshold[3] = {0.9, 0.8, 0.3};
  const double precision[3][2] = {{1, 1}, {1.0 / 3, 2.0 / 3}, {0.25, 0.75}};
  const double recall[3][2] = {{0.25, 0.25}, {0.25, 0.5}, {0.25, 0.75}};
  for (int p = 0; p < 3; ++p) {
    EXPECT_EQ(curve[p].threshold, threshold[p]);
    EXPECT_EQ(curve[p].accepted, accepted[p]);
    for (int k = 0; k < 2; ++k) {
      EXPECT_DOUBLE_EQ(curve[p].precision[k], precision[p][k]) << p << ' ' << k;
      EXPECT_DOUBLE_EQ(curve[p].recall[k], recall[p][k]) << p << ' ' << k;
    }
  }
  EXPECT_TRUE(PrecisionRecallCurve({}, {}, {}, {2}).empty());
}

// NearestPlaceDistances: per query, the nearest place on its own floor within the reach.
TEST(PrecisionRecallTest, NearestPlaceDistancesRespectFloorAndReach) {
  std::vector<EvaluationNode> map(3), queries(3);
  map[0].x_m = 0;
  map[1].x_m = 10;
  map[2].x_m = 3;
  map[2].floor = 1;
  queries[0].x_m = 1;  // 1 m from place 0
  queries[1].x_m = 3;
  queries[1].floor = 1;  // on place 2
  queries[2].x_m = 40;   // 30 m from place 1: beyond a 20 m reach
  const std::vector<double> d = NearestPlaceDistances(map, queries, 20);
  EXPECT_DOUBLE_EQ(d[0], 1.0);
  EXPECT_DOUBLE_EQ(d[1], 0.0);
  EXPECT_TRUE(std::isinf(d[2]));
}

// Six queries with known nearest map distances and answers: near ones (<= 5 m) were answered
// located, rejected and on another floor; far ones (> 10 m) rejected twice and located once; one
// at 7 m is in neither group.
TEST(MapDistanceTest, GroupsByNearestPlace) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EvaluationMetrics m;
  m.errors_m = {1.0, nan, inf, nan, nan, 14.0, 3.0};
  const std::vector<double> nearest = {0.5, 5.0, 2.0, 11.0, inf, 12.0, 7.0};
  const MapDistanceReport r = ByMapDistance(m, nearest, 5.0, 10.0);
  EXPECT_EQ(r.near.queries, 3u);
  EXPECT_DOUBLE_EQ(r.near.rejection_rate, 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(r.near.floor_mistake_rate, 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(r.near.located_rate, 1.0 / 3.0);
  EXPECT_EQ(r.far.queries, 3u);
  EXPECT_DOUBLE_EQ(r.far.rejection_rate, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(r.far.floor_mistake_rate, 0.0);
  EXPECT_DOUBLE_EQ(r.far.located_rate, 1.0 / 3.0);
}

TEST(NewPlaceThresholdTest, SeparableScoresGetTheMidpoint) {
  // Near nodes score 5, 6, 7; far ones 1, 2, 3: any t in [3, 5) separates them; the sweep takes
  // the first maximum, past the score 3, at the midpoint 4.
  const NewPlaceThreshold t = LearnNewPlaceThreshold(
      {5, 1, 6, 2, 7, 3}, {true, false, true, false, true, false}, NewPlaceRule::kYouden, 0.95);
  ASSERT_TRUE(t.calibrated);
  EXPECT_DOUBLE_EQ(t.log_odds, 4.0);
  EXPECT_EQ(t.near, 3u);
  EXPECT_EQ(t.far, 3u);
  EXPECT_DOUBLE_EQ(t.near_accepted, 1.0);
  EXPECT_DOUBLE_EQ(t.far_rejected, 1.0);
}

TEST(NewPlaceThresholdTest, OverlappingScoresMaximiseYoudensJ) {
  // Near 2, 6, 7, 9; far 1, 3, 4, -inf (no mapped place), NaN (counted as -inf). By hand, J at
  // each candidate (near accepted + far rejected - 1): accept all finite: 1 + 2/5 - 1 = 0.4;
  // t between 1 and 2: 1 + 3/5 - 1 = 0.6; between 2 and 3: 3/4 + 3/5 - 1 = 0.35; between 3
  // and 4: 3/4 + 4/5 - 1 = 0.55; between 4 and 6: 3/4 + 1 - 1 = 0.75 (the best); higher t
  // accepts fewer near nodes at no gain.
  const double inf = std::numeric_limits<double>::infinity();
  const NewPlaceThreshold t = LearnNewPlaceThreshold(
      {2, 6, 7, 9, 1, 3, 4, -inf, std::nan("")},
      {true, true, true, true, false, false, false, false, false}, NewPlaceRule::kYouden, 0.95);
  ASSERT_TRUE(t.calibrated);
  EXPECT_DOUBLE_EQ(t.log_odds, 5.0);
  EXPECT_DOUBLE_EQ(t.near_accepted, 0.75);
  EXPECT_DOUBLE_EQ(t.far_rejected, 1.0);
}

TEST(MapDistanceTest, FarMustNotBeNearerThanNear) {
  EvaluationOptions options;
  std::string error;
  EXPECT_TRUE(options.IsValid(&error)) << error;
  options.far_place_m = 4.0;  // below near_place_m = 5
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("far_place_m"), std::string::npos) << error;
}

TEST(NewPlaceThresholdTest, YoudenNeedsBothKindsOfNode) {
  const NewPlaceThreshold t =
      LearnNewPlaceThreshold({5, 6}, {true, true}, NewPlaceRule::kYouden, 0.95);
  EXPECT_FALSE(t.calibrated);
  EXPECT_EQ(t.log_odds, 0.0);
  EXPECT_EQ(t.near, 2u);
  EXPECT_EQ(t.far, 0u);
  EXPECT_FALSE(LearnNewPlaceThreshold({}, {}, NewPlaceRule::kYouden, 0.95).calibrated);
}

TEST(NewPlaceThresholdTest, NearRecallRejectsTheLowestShareOfNearNodes) {
  // Near nodes score 20, 19, ..., 1 (shuffled in with far ones at 0.5, 3 and 30). Recall 0.95
  // of 20 allows floor(0.05 x 20) = 1 rejection: t halfway between 1 and 2. Far nodes are only
  // reported: 0.5 rejected, 3 and 30 accepted.
  std::vector<double> scores = {0.5, 3, 30};
  std::vector<bool> near = {false, false, false};
  for (int v = 20; v >= 1; --v) {
    scores.push_back(v);
    near.push_back(true);
  }
  const NewPlaceThreshold t = LearnNewPlaceThreshold(scores, near, NewPlaceRule::kNearRecall, 0.95);
  ASSERT_TRUE(t.calibrated);
  EXPECT_DOUBLE_EQ(t.log_odds, 1.5);
  EXPECT_EQ(t.near, 20u);
  EXPECT_EQ(t.far, 3u);
  EXPECT_DOUBLE_EQ(t.near_accepted, 0.95);
  EXPECT_DOUBLE_EQ(t.far_rejected, 1.0 / 3.0);
  // Recall 0.8 allows 4 rejections (t = 4.5); 0.79 still 4 (floor of 4.2); 1 none (t = -inf).
  EXPECT_DOUBLE_EQ(LearnNewPlaceThreshold(scores, near, NewPlaceRule::kNearRecall, 0.8).log_odds,
                   4.5);
  EXPECT_DOUBLE_EQ(LearnNewPlaceThreshold(scores, near, NewPlaceRule::kNearRecall, 0.79).log_odds,
                   4.5);
  EXPECT_EQ(LearnNewPlaceThreshold(scores, near, NewPlaceRule::kNearRecall, 1.0).log_odds,
            -std::numeric_limits<double>::infinity());
}

TEST(NewPlaceThresholdTest, NearRecallNeverSplitsATieAndNeedsNoFarNodes) {
  const double inf = std::numeric_limits<double>::infinity();
  // Near 1, 1, 2, 3: recall 0.75 allows one rejection, but the two 1s stand or fall together, so
  // none is rejected: t = -inf. No far node: still calibrated, far_rejected 0.
  NewPlaceThreshold t = LearnNewPlaceThreshold({2, 1, 3, 1}, {true, true, true, true},
                                               NewPlaceRule::kNearRecall, 0.75);
  ASSERT_TRUE(t.calibrated);
  EXPECT_EQ(t.log_odds, -inf);
  EXPECT_DOUBLE_EQ(t.near_accepted, 1.0);
  EXPECT_EQ(t.far, 0u);
  EXPECT_DOUBLE_EQ(t.far_rejected, 0.0);
  // Near NaN (no mapped place: -inf), 5, 6, 7: the one rejection allowed is the NaN, which is
  // rejected at every threshold; t stays -inf, 3 of 4 accepted.
  t = LearnNewPlaceThreshold({std::nan(""), 5, 6, 7}, {true, true, true, true},
                             NewPlaceRule::kNearRecall, 0.75);
  EXPECT_EQ(t.log_odds, -inf);
  EXPECT_DOUBLE_EQ(t.near_accepted, 0.75);
  // Only far nodes: nothing to learn from.
  EXPECT_FALSE(
      LearnNewPlaceThreshold({1, 2}, {false, false}, NewPlaceRule::kNearRecall, 0.95).calibrated);
}

}  // namespace
}  // namespace ratslam::fabmap
