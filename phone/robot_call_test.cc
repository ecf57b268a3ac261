#include "phone/robot_call.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <set>
#include <vector>

namespace ratslam::phone {
namespace {

// A w x h lattice of unit spacing, node y * w + x, 4-connected.
RouteGraph Lattice(int w, int h) {
  RouteGraph g;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) g.nodes.push_back({double(x), double(y)});
  }
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const uint32_t k = static_cast<uint32_t>(y * w + x);
      if (x + 1 < w) g.edges.push_back({k, k + 1});
      if (y + 1 < h) g.edges.push_back({k, k + static_cast<uint32_t>(w)});
    }
  }
  return g;
}

// Oracle: all-pairs shortest paths by Floyd-Warshall, then the best open tour over every
// permutation of the stops.
double BruteForceTour(const RouteGraph& g, uint32_t start, std::vector<uint32_t> stops) {
  const size_t n = g.nodes.size();
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<std::vector<double>> d(n, std::vector<double>(n, inf));
  for (size_t k = 0; k < n; ++k) d[k][k] = 0;
  for (const auto& [a, b] : g.edges) {
    const double w = std::hypot(g.nodes[a].x - g.nodes[b].x, g.nodes[a].y - g.nodes[b].y);
    d[a][b] = std::min(d[a][b], w);
    d[b][a] = std::min(d[b][a], w);
  }
  for (size_t k = 0; k < n; ++k) {
    for (size_t i = 0; i < n; ++i) {
      for (size_t j = 0; j < n; ++j) d[i][j] = std::min(d[i][j], d[i][k] + d[k][j]);
    }
  }
  std::sort(stops.begin(), stops.end());
  double best = inf;
  do {
    double length = 0;
    uint32_t at = start;
    for (uint32_t s : stops) {
      length += d[at][s];
      at = s;
    }
    best = std::min(best, length);
  } while (std::next_permutation(stops.begin(), stops.end()));
  return best;
}

void ExpectRouteFollowsTheGraph(const RouteGraph& g, const CallPlan& plan, uint32_t start) {
  ASSERT_FALSE(plan.route.empty());
  EXPECT_EQ(plan.route.front(), start);
  std::set<std::pair<uint32_t, uint32_t>> edges;
  for (const auto& [a, b] : g.edges) {
    edges.insert({a, b});
    edges.insert({b, a});
  }
  double length = 0;
  for (size_t k = 1; k < plan.route.size(); ++k) {
    const uint32_t a = plan.route[k - 1], b = plan.route[k];
    EXPECT_TRUE(edges.count({a, b})) << a << "-" << b << " is not an edge";
    length += std::hypot(g.nodes[a].x - g.nodes[b].x, g.nodes[a].y - g.nodes[b].y);
  }
  EXPECT_NEAR(length, plan.length_m, 1e-9);
  // Every stop is on the route, in the planned order.
  size_t at = 0;
  for (uint32_t stop : plan.stops) {
    while (at < plan.route.size() && plan.route[at] != stop) ++at;
    EXPECT_LT(at, plan.route.size()) << "stop " << stop << " missing or out of order";
  }
}

TEST(RobotCallTest, VisitsEveryCandidateOnALatticeOptimally) {
  const RouteGraph g = Lattice(6, 5);
  const std::vector<Point2> candidates = {{5.1, 4.2}, {0.2, 3.9}, {2.8, 0.1}, {4.9, 0.3}};
  StatusOr<CallPlan> plan = PlanCall(g, 0, candidates);
  ASSERT_TRUE(plan.ok()) << plan.status().message();
  EXPECT_TRUE(plan->exact);
  // Each candidate is served by the lattice node it lies nearest.
  EXPECT_EQ(plan->serving_node, (std::vector<uint32_t>{29, 24, 3, 5}));
  EXPECT_NEAR(plan->serving_distance_m[0], std::hypot(0.1, 0.2), 1e-12);
  std::set<size_t> served;
  for (const auto& s : plan->stop_candidates) served.insert(s.begin(), s.end());
  EXPECT_EQ(served.size(), candidates.size());
  ExpectRouteFollowsTheGraph(g, *plan, 0);
  // From (0,0): (3,0), (5,0), (5,4), (0,4) is 3 + 2 + 4 + 5 = 14 m, the best open tour.
  EXPECT_DOUBLE_EQ(plan->length_m, 14.0);
  EXPECT_DOUBLE_EQ(plan->length_m, BruteForceTour(g, 0, {3, 5, 29, 24}));
}

TEST(RobotCallTest, HeldKarpMatchesBruteForceOnRandomGraphs) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(0.0, 30.0);
  for (int trial = 0; trial < 20; ++trial) {
    RouteGraph g;
    const uint32_t n = 40;
    for (uint32_t k = 0; k < n; ++k) g.nodes.push_back({coordinate(random), coordinate(random)});
    // A random spanning tree plus extra edges: connected, with alternative paths.
    for (uint32_t k = 1; k < n; ++k) g.edges.push_back({k, static_cast<uint32_t>(random() % k)});
    for (int e = 0; e < 30; ++e) {
      g.edges.push_back({static_cast<uint32_t>(random() % n), static_cast<uint32_t>(random() % n)});
    }
    std::vector<Point2> candidates;
    for (int c = 0; c < 7; ++c) candidates.push_back({coordinate(random), coordinate(random)});
    const uint32_t start = static_cast<uint32_t>(random() % n);
    StatusOr<CallPlan> plan = PlanCall(g, start, candidates);
    ASSERT_TRUE(plan.ok()) << plan.status().message();
    ExpectRouteFollowsTheGraph(g, *plan, start);
    EXPECT_NEAR(plan->length_m, BruteForceTour(g, start, plan->stops), 1e-9) << "trial " << trial;
  }
}

TEST(RobotCallTest, HeuristicBeyondTheExactLimitOnALine) {
  // A line of 60 nodes, the robot at one end, 20 candidates along it: the best open tour walks
  // to the farthest, and nearest neighbour + 2-opt must find it.
  RouteGraph g;
  for (uint32_t k = 0; k < 60; ++k) {
    g.nodes.push_back({double(k), 0.0});
    if (k > 0) g.edges.push_back({k - 1, k});
  }
  std::vector<Point2> candidates;
  for (int c = 0; c < 20; ++c) candidates.push_back({3.0 + 2.0 * ((c * 7) % 20), 0.4});
  StatusOr<CallPlan> plan = PlanCall(g, 0, candidates);
  ASSERT_TRUE(plan.ok());
  EXPECT_FALSE(plan->exact);
  EXPECT_EQ(plan->stops.size(), 20u);
  EXPECT_NEAR(plan->length_m, 3.0 + 2.0 * 19, 1e-9);
  ExpectRouteFollowsTheGraph(g, *plan, 0);
}

TEST(RobotCallTest, UnreachableNodesDoNotServeAndBadInputFails) {
  // Two components: a candidate beside the far one is served by the nearest reachable node.
  RouteGraph g;
  g.nodes = {{0, 0}, {1, 0}, {2, 0}, {50, 0}, {51, 0}};
  g.edges = {{0, 1}, {1, 2}, {3, 4}};
  StatusOr<CallPlan> plan = PlanCall(g, 0, {{50.5, 0}, {0.1, 0.1}});
  ASSERT_TRUE(plan.ok());
  EXPECT_EQ(plan->serving_node, (std::vector<uint32_t>{2, 0}));
  EXPECT_EQ(plan->stops, (std::vector<uint32_t>{2}));
  EXPECT_DOUBLE_EQ(plan->length_m, 2.0);
  // A candidate at the robot: no travel.
  plan = PlanCall(g, 0, {{0, 0}});
  ASSERT_TRUE(plan.ok());
  EXPECT_EQ(plan->route, (std::vector<uint32_t>{0}));
  EXPECT_EQ(plan->length_m, 0.0);
  EXPECT_FALSE(PlanCall(g, 0, {}).ok());
  EXPECT_FALSE(PlanCall(g, 9, {{0, 0}}).ok());
  EXPECT_FALSE(PlanCall(g, 0, {{NAN, 0}}).ok());
  g.edges.push_back({0, 7});
  EXPECT_FALSE(PlanCall(g, 0, {{1, 0}}).ok());
}

}  // namespace
}  // namespace ratslam::phone
