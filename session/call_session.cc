#include "session/call_session.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include "common/file_util.h"
#include "common/number_text.h"
#include "io/map_file.h"
#include "io/run_reader.h"

namespace ratslam::session {

StatusOr<RobotMap> LoadRobotMap(const std::string& path) {
  RobotMap m;
  if (IsDirectory(path)) {
    StatusOr<io::RunFolder> run = io::ReadRunFolder(path);
    if (!run.ok()) return run.status();
    m.experiences = std::move(run->experiences);
    m.links = std::move(run->links);
    m.current = run->current_experience;
    for (auto f = run->frames.rbegin(); f != run->frames.rend() && !m.current; ++f) {
      if (f->experience_id >= 0 && f->experience_id < static_cast<int64_t>(m.experiences.size())) {
        m.current = static_cast<uint32_t>(f->experience_id);
      }
    }
  } else {
    StatusOr<io::MapFile> map = io::LoadMapFile(path);
    if (!map.ok()) return map.status();
    const ExperienceMap::State& state = map->state.ratslam.experience_map;
    m.experiences = state.experiences;
    m.links = state.links;
    m.current = state.current;
  }
  if (m.experiences.empty()) return Status::Error(path + ": the map has no experience");
  if (!m.current) m.current = static_cast<uint32_t>(m.experiences.size() - 1);
  return m;
}

std::string CallResult::RouteCsv() const {
  std::ostringstream route;
  route << "step,experience_id,x_m,y_m,stop_of_candidates\n";
  size_t next_stop = 0;
  for (size_t k = 0; k < plan.route.size(); ++k) {
    const uint32_t e = plan.route[k];
    route << k << ',' << e << ',' << ShortestNumber(graph.nodes[e].x) << ','
          << ShortestNumber(graph.nodes[e].y) << ',';
    if (next_stop < plan.stops.size() && plan.stops[next_stop] == e) {
      for (size_t c = 0; c < plan.stop_candidates[next_stop].size(); ++c) {
        route << (c ? " " : "") << plan.stop_candidates[next_stop][c];
      }
      ++next_stop;
    }
    route << '\n';
  }
  return route.str();
}

StatusOr<CallResult> CallRobot(const PhoneSetup& setup, const RobotMap& robot, double at_s,
                               const CallLabels& labels) {
  const phone::WifiGpMap& map = setup.map;
  const dataset::Dataset& d = setup.data;
  if (d.wifi.empty() || d.wifi.front().time_s > at_s) {
    return Status::Error(
        labels.data + ": no Wi-Fi scan at or before --at " + ShortestNumber(at_s) +
        (d.wifi.empty() ? " s (the log has none)"
                        : " s (the first is at " + ShortestNumber(d.wifi.front().time_s) + " s)"));
  }
  if (!robot.current || *robot.current >= robot.experiences.size()) {
    return Status::Error(labels.map + ": the robot's experience is not in its map");
  }
  phone::ParticleFilter filter(map, setup.options.particle_filter);
  Status initialised = filter.Initialise(!d.compass.empty());
  if (!initialised.ok()) return initialised;
  CallResult r;
  FilterPhoneLog(d, map, &filter, at_s, [&](const WifiScan& scan, size_t) {
    ++r.scans_used;
    r.last_scan_s = scan.time_s;
  });
  r.estimate = filter.Estimate();
  r.candidates = filter.Candidates();
  r.particles = filter.particles();
  std::vector<Point2> candidates;
  for (const auto& c : r.candidates) candidates.push_back(c.first);
  for (const Experience& e : robot.experiences) r.graph.nodes.push_back({e.x_m, e.y_m});
  for (const Link& l : robot.links) r.graph.edges.push_back({l.from, l.to});
  StatusOr<phone::CallPlan> plan = phone::PlanCall(r.graph, *robot.current, candidates);
  if (!plan.ok()) return plan.status();
  r.plan = std::move(plan).value();

  nlohmann::ordered_json& j = r.summary;
  j["data"] = labels.data;
  j["map"] = labels.map;
  j["wifi_map"] = labels.wifi_map;
  j["at_s"] = at_s;
  j["scans_used"] = r.scans_used;
  j["last_scan_s"] = r.last_scan_s;
  j["robot_experience"] = *robot.current;
  j["estimate"] = {{"x_m", r.estimate.x_m}, {"y_m", r.estimate.y_m}, {"floor", r.estimate.floor}};
  if (const auto truth = dataset::GroundTruthAt(d, r.last_scan_s)) {
    r.truth_on_map = TruthToMap(map, {truth->x_m, truth->y_m});
    const Point2& t = *r.truth_on_map;
    j["truth_on_map"] = {{"x_m", t.x}, {"y_m", t.y}};
    j["estimate_error_m"] = std::hypot(r.estimate.x_m - t.x, r.estimate.y_m - t.y);
    double nearest = std::numeric_limits<double>::infinity();
    for (const Point2& c : candidates)
      nearest = std::min(nearest, std::hypot(c.x - t.x, c.y - t.y));
    j["nearest_candidate_error_m"] = nearest;
  }
  nlohmann::ordered_json cs = nlohmann::ordered_json::array();
  for (size_t k = 0; k < r.candidates.size(); ++k) {
    cs.push_back({{"rank", k},
                  {"x_m", r.candidates[k].first.x},
                  {"y_m", r.candidates[k].first.y},
                  {"weight", r.candidates[k].second},
                  {"experience", r.plan.serving_node[k]},
                  {"distance_to_experience_m", r.plan.serving_distance_m[k]}});
  }
  j["candidates"] = cs;
  j["stops"] = r.plan.stops;
  j["tour"] = r.plan.exact ? "exact (Held-Karp)" : "nearest neighbour + 2-opt";
  j["route_experiences"] = r.plan.route.size();
  j["route_length_m"] = r.plan.length_m;
  return r;
}

}  // namespace ratslam::session
