// Calling the robot to a located phone (Kudo and Miura, section IV-C.2): the robot, at a node of
// its map's graph (an experience), visits every candidate location of the phone along the graph.
//
//  - Each candidate is served by the node nearest to it among those the robot can reach (the
//    graph need not be connected); candidates served by the same node, or by the robot's own,
//    are one stop.
//  - Travel between stops is the shortest path over the graph (Dijkstra), an edge costing the
//    straight distance between its nodes' positions on the map, so the route's length is the
//    length of the line drawn through its nodes.
//  - The visiting order is an open tour from the robot's node (no return): exact by Held-Karp
//    dynamic programming over subsets for up to kExactStops stops (the paper's twelve
//    candidates take 12 x 2^12 states), otherwise nearest neighbour improved by 2-opt until no
//    reversal shortens it. Ties break by lower index, so a plan is deterministic.
#ifndef RATSLAM_PHONE_ROBOT_CALL_H_
#define RATSLAM_PHONE_ROBOT_CALL_H_

#include <cstdint>
#include <utility>
#include <vector>

#include "common/geometry.h"
#include "common/status.h"

namespace ratslam::phone {

struct RouteGraph {
  std::vector<Point2> nodes;                         // positions on the map
  std::vector<std::pair<uint32_t, uint32_t>> edges;  // undirected
};

struct CallPlan {
  // Per candidate (in the order given): the node serving it and its distance from it.
  std::vector<uint32_t> serving_node;
  std::vector<double> serving_distance_m;
  // The stops (distinct serving nodes other than the start) in visiting order, and for each the
  // candidates it serves.
  std::vector<uint32_t> stops;
  std::vector<std::vector<size_t>> stop_candidates;
  std::vector<uint32_t> route;  // nodes from the start through every stop (consecutive: linked)
  double length_m = 0.0;
  bool exact = false;  // Held-Karp (optimal order) rather than the heuristic
};

inline constexpr size_t kExactStops = 13;

// Fails on no candidate, a start that is not a node, an edge to a missing node, or a
// non-finite position.
StatusOr<CallPlan> PlanCall(const RouteGraph& graph, uint32_t start,
                            const std::vector<Point2>& candidates);

// Shortest path lengths from `source` to every node (infinity where unreachable) and each
// node's predecessor on it (itself for the source and unreachable nodes).
void ShortestPaths(const RouteGraph& graph, uint32_t source, std::vector<double>* distance_m,
                   std::vector<uint32_t>* previous);

}  // namespace ratslam::phone

#endif  // RATSLAM_PHONE_ROBOT_CALL_H_
