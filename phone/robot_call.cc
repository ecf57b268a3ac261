#include "phone/robot_call.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <string>

namespace ratslam::phone {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double Distance(const Point2& a, const Point2& b) { return std::hypot(a.x - b.x, a.y - b.y); }

// Exact open tour from 0 through all of 1..n-1 (Held-Karp). Returns the order of 1..n-1.
std::vector<size_t> HeldKarp(const std::vector<std::vector<double>>& d) {
  const size_t n = d.size() - 1;  // stops besides the start
  const size_t full = (size_t{1} << n) - 1;
  // cost[set][last]: shortest path from 0 through `set` ending at stop last+1.
  std::vector<double> cost((full + 1) * n, kInf);
  std::vector<int8_t> parent((full + 1) * n, -1);
  for (size_t k = 0; k < n; ++k) cost[(size_t{1} << k) * n + k] = d[0][k + 1];
  for (size_t set = 1; set <= full; ++set) {
    for (size_t last = 0; last < n; ++last) {
      const double here = cost[set * n + last];
      if (!(set >> last & 1) || here == kInf) continue;
      for (size_t next = 0; next < n; ++next) {
        if (set >> next & 1) continue;
        const size_t grown = set | size_t{1} << next;
        const double c = here + d[last + 1][next + 1];
        if (c < cost[grown * n + next]) {
          cost[grown * n + next] = c;
          parent[grown * n + next] = static_cast<int8_t>(last);
        }
      }
    }
  }
  size_t last = 0;
  for (size_t k = 1; k < n; ++k) {
    if (cost[full * n + k] < cost[full * n + last]) last = k;
  }
  std::vector<size_t> order;
  for (size_t set = full; set != 0;) {
    order.push_back(last + 1);
    const int8_t p = parent[set * n + last];
    set &= ~(size_t{1} << last);
    if (p < 0) break;
    last = static_cast<size_t>(p);
  }
  std::reverse(order.begin(), order.end());
  return order;
}

double OpenTourLength(const std::vector<std::vector<double>>& d, const std::vector<size_t>& order) {
  double length = 0.0;
  size_t at = 0;
  for (size_t s : order) {
    length += d[at][s];
    at = s;
  }
  return length;
}

// Nearest neighbour from 0, then 2-opt reversals of the open path while one shortens it.
std::vector<size_t> NearestNeighbourTwoOpt(const std::vector<std::vector<double>>& d) {
  const size_t n = d.size();
  std::vector<size_t> order;
  std::vector<bool> used(n, false);
  used[0] = true;
  for (size_t at = 0; order.size() + 1 < n;) {
    size_t best = n;
    for (size_t k = 1; k < n; ++k) {
      if (!used[k] && (best == n || d[at][k] < d[at][best])) best = k;
    }
    used[best] = true;
    order.push_back(best);
    at = best;
  }
  for (bool improved = true; improved;) {
    improved = false;
    for (size_t i = 0; i < order.size(); ++i) {
      for (size_t j = i + 1; j < order.size(); ++j) {
        // Reverse order[i..j]: the edge into i and the edge out of j change.
        const size_t before = i == 0 ? 0 : order[i - 1];
        const bool open_end = j + 1 == order.size();
        const double old_cost = d[before][order[i]] + (open_end ? 0.0 : d[order[j]][order[j + 1]]);
        const double new_cost = d[before][order[j]] + (open_end ? 0.0 : d[order[i]][order[j + 1]]);
        if (new_cost < old_cost - 1e-9) {
          std::reverse(order.begin() + static_cast<std::ptrdiff_t>(i),
                       order.begin() + static_cast<std::ptrdiff_t>(j) + 1);
          improved = true;
        }
      }
    }
  }
  return order;
}

}  // namespace

void ShortestPaths(const RouteGraph& graph, uint32_t source, std::vector<double>* distance_m,
                   std::vector<uint32_t>* previous) {
  const size_t n = graph.nodes.size();
  std::vector<std::vector<std::pair<uint32_t, double>>> adjacent(n);
  for (const auto& [a, b] : graph.edges) {
    const double w = Distance(graph.nodes[a], graph.nodes[b]);
    adjacent[a].emplace_back(b, w);
    adjacent[b].emplace_back(a, w);
  }
  distance_m->assign(n, kInf);
  previous->resize(n);
  for (size_t k = 0; k < n; ++k) (*previous)[k] = static_cast<uint32_t>(k);
  using Item = std::pair<double, uint32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  (*distance_m)[source] = 0.0;
  queue.emplace(0.0, source);
  while (!queue.empty()) {
    const auto [d, at] = queue.top();
    queue.pop();
    if (d > (*distance_m)[at]) continue;
    for (const auto& [to, w] : adjacent[at]) {
      if (d + w < (*distance_m)[to]) {
        (*distance_m)[to] = d + w;
        (*previous)[to] = at;
        queue.emplace(d + w, to);
      }
    }
  }
}

StatusOr<CallPlan> PlanCall(const RouteGraph& graph, uint32_t start,
                            const std::vector<Point2>& candidates) {
  const size_t n = graph.nodes.size();
  if (candidates.empty()) return Status::Error("calling the robot: no candidate location");
  if (start >= n) {
    return Status::Error("calling the robot: the robot's node " + std::to_string(start) +
                         " is not in the graph (" + std::to_string(n) + " nodes)");
  }
  for (const Point2& p : graph.nodes) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      return Status::Error("calling the robot: a node's position is not finite");
    }
  }
  for (const Point2& p : candidates) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      return Status::Error("calling the robot: a candidate's position is not finite");
    }
  }
  for (const auto& [a, b] : graph.edges) {
    if (a >= n || b >= n) return Status::Error("calling the robot: an edge to a missing node");
  }
  std::vector<double> from_start;
  std::vector<uint32_t> previous;
  ShortestPaths(graph, start, &from_start, &previous);

  CallPlan plan;
  for (const Point2& c : candidates) {
    uint32_t best = start;
    double best_d = Distance(c, graph.nodes[start]);
    for (uint32_t k = 0; k < n; ++k) {
      if (from_start[k] == kInf) continue;
      const double dk = Distance(c, graph.nodes[k]);
      if (dk < best_d) {
        best = k;
        best_d = dk;
      }
    }
    plan.serving_node.push_back(best);
    plan.serving_distance_m.push_back(best_d);
  }
  // Stops: distinct serving nodes other than the start, in order of first candidate.
  std::vector<uint32_t> stops;
  std::vector<std::vector<size_t>> served;
  for (size_t c = 0; c < candidates.size(); ++c) {
    const uint32_t node = plan.serving_node[c];
    if (node == start) continue;
    auto it = std::find(stops.begin(), stops.end(), node);
    if (it == stops.end()) {
      stops.push_back(node);
      served.emplace_back();
      it = stops.end() - 1;
    }
    served[static_cast<size_t>(it - stops.begin())].push_back(c);
  }
  plan.route = {start};
  if (stops.empty()) {
    plan.exact = true;
    return plan;
  }
  // Distances between the start (index 0) and the stops (1..), with paths.
  std::vector<uint32_t> points = {start};
  points.insert(points.end(), stops.begin(), stops.end());
  const size_t m = points.size();
  std::vector<std::vector<double>> d(m, std::vector<double>(m, 0.0));
  std::vector<std::vector<uint32_t>> previous_from(m);
  for (size_t a = 0; a < m; ++a) {
    std::vector<double> dist;
    if (a == 0) {
      dist = from_start;
      previous_from[0] = previous;
    } else {
      ShortestPaths(graph, points[a], &dist, &previous_from[a]);
    }
    for (size_t b = 0; b < m; ++b) d[a][b] = dist[points[b]];
  }
  plan.exact = stops.size() <= kExactStops;
  const std::vector<size_t> order = plan.exact ? HeldKarp(d) : NearestNeighbourTwoOpt(d);
  plan.length_m = OpenTourLength(d, order);
  size_t at = 0;
  for (size_t s : order) {
    plan.stops.push_back(points[s]);
    plan.stop_candidates.push_back(served[s - 1]);
    // The path from points[at] to points[s], read back from points[s] over at's predecessors.
    std::vector<uint32_t> leg;
    for (uint32_t k = points[s]; k != points[at]; k = previous_from[at][k]) leg.push_back(k);
    plan.route.insert(plan.route.end(), leg.rbegin(), leg.rend());
    at = s;
  }
  return plan;
}

}  // namespace ratslam::phone
