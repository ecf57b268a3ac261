// A replay's run folder as `ratslam call` and `ratslam wifi-map --run` read it: experiences.csv,
// links.csv, frames.csv, summary.json and trajectory_tum.txt, fuzzed as one input whose parts
// are separated by a line "%%". Errors name a file of the folder; a folder that reads plans a
// robot call over its experience graph (every candidate served by a reachable experience, the
// route along links), and a trajectory that reads has strictly increasing, finite times.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "fuzz/fuzz_support.h"
#include "io/run_reader.h"
#include "phone/robot_call.h"

namespace ratslam::fuzz {
namespace {
const char* const kFiles[] = {"experiences.csv", "links.csv", "frames.csv", "summary.json",
                              "trajectory_tum.txt"};
}  // namespace

std::vector<std::string> FuzzSeeds() {
  return {std::string(
              "id,x_m,y_m,theta_rad,template_id,time_s,pose_cell_x,pose_cell_y,pose_cell_theta\n"
              "0,0,0,0,0,0.5,1,1,0\n1,2,0,0.1,1,1.5,2,1,0\n2,2,2,1.6,2,2.5,2,2,1\n"
              "3,50,50,0,3,3.5,5,5,5\n") +
          "\n%%\nid,from_id,to_id,distance_m,heading_rad,facing_rad,duration_s,loop_closure,"
          "kind\n0,0,1,2,0,0.1,1,0,odometry\n1,1,2,2,1.5,1.5,1,0,odometry\n"
          "2,2,0,2.8,-2.3,-1.6,1,1,loop_closure\n" +
          "\n%%\ntime_s,template_id,new_template,experience_id,source,recent\n"
          "0.5,0,1,0,new,0\n1.5,1,1,1,new,0\n2.5,0,0,2,wifi,1\n" +
          "\n%%\n{\"dataset\": \"seed\", \"current_experience\": 2}\n" +
          "\n%%\n# timestamp tx ty tz qx qy qz qw\n0.5 0 0 0 0 0 0 1\n"
          "1.5 2 0 0 0 0 0.05 0.9987\n2.5 2 2 0 0 0 0.7 0.714\n"};
}

}  // namespace ratslam::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ratslam;
  namespace fs = std::filesystem;
  const std::vector<std::string> parts = fuzz::SplitParts(data, size, "\n%%\n");
  const fs::path folder =
      fuzz::WriteScratchFolder("run", parts, {std::begin(fuzz::kFiles), std::end(fuzz::kFiles)});
  StatusOr<std::vector<GroundTruthRow>> trajectory =
      io::ReadTumTrajectory((folder / "trajectory_tum.txt").string());
  if (!trajectory.ok()) {
    if (trajectory.status().message().rfind(folder.string(), 0) != 0) {
      fuzz::InvariantFailed("TUM error does not name the file: " + trajectory.status().message());
    }
  } else {
    for (size_t k = 0; k < trajectory->size(); ++k) {
      const GroundTruthRow& r = (*trajectory)[k];
      if (!std::isfinite(r.time_s) || !std::isfinite(r.x_m) || !std::isfinite(r.y_m) ||
          !std::isfinite(r.theta_rad) || (k > 0 && !(r.time_s > (*trajectory)[k - 1].time_s))) {
        fuzz::InvariantFailed("a trajectory read with a non-finite value or a time not after");
      }
    }
  }
  StatusOr<io::RunFolder> run = io::ReadRunFolder(folder.string());
  if (!run.ok()) {
    if (run.status().message().rfind(folder.string(), 0) != 0) {
      fuzz::InvariantFailed("error does not name a file of the run: " + run.status().message());
    }
    return 0;
  }
  if (run->experiences.empty() || run->experiences.size() > 5000) return 0;
  phone::RouteGraph graph;
  for (const Experience& e : run->experiences) graph.nodes.push_back({e.x_m, e.y_m});
  for (const Link& l : run->links) graph.edges.push_back({l.from, l.to});
  const uint32_t start = run->current_experience.value_or(0);
  const std::vector<Point2> candidates = {{0, 0}, {1.5, -2}, {1e6, 3}, {-7, 7}};
  StatusOr<phone::CallPlan> plan = phone::PlanCall(graph, start, candidates);
  if (!plan.ok()) return 0;  // e.g. a non-finite position: refused, not planned
  std::set<std::pair<uint32_t, uint32_t>> linked;
  for (const auto& [a, b] : graph.edges) linked.insert({std::min(a, b), std::max(a, b)});
  if (plan->route.empty() || plan->route.front() != start) fuzz::InvariantFailed("route start");
  for (size_t k = 1; k < plan->route.size(); ++k) {
    const uint32_t a = plan->route[k - 1], b = plan->route[k];
    if (!linked.count({std::min(a, b), std::max(a, b)})) {
      fuzz::InvariantFailed("the route leaves the graph");
    }
  }
  for (uint32_t node : plan->serving_node) {
    if (node != start &&
        std::find(plan->route.begin(), plan->route.end(), node) == plan->route.end()) {
      fuzz::InvariantFailed("a candidate's experience is not visited");
    }
  }
  if (!(plan->length_m >= 0)) fuzz::InvariantFailed("route length negative or NaN");
  return 0;
}
