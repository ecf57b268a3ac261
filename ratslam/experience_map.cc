#include "ratslam/experience_map.h"

#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/dijkstra_shortest_paths.hpp>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/circular.h"
#include "common/geometry.h"

namespace ratslam {

bool ExperienceMapOptions::IsValid(std::string* error) const {
  return schema::CheckFields(*this, error);
}

ExperienceMap::ExperienceMap(const ExperienceMapOptions& options) : options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("ExperienceMapOptions: " + error);
}

void ExperienceMap::Integrate(double forward_m, double rotation_rad) {
  LocalOffset& o = state_.offset;
  Pose2 pose{o.forward_m, o.left_m, o.facing_rad};
  AdvanceMidpoint(&pose, forward_m, rotation_rad);
  o = {pose.x_m, pose.y_m, pose.theta_rad};
}

void ExperienceMap::CurrentPose(double* x_m, double* y_m, double* theta_rad) const {
  Pose2 base;
  if (state_.current) {
    const Experience& e = state_.experiences[*state_.current];
    base = {e.x_m, e.y_m, e.theta_rad};
  }
  const LocalOffset& o = state_.offset;
  const Pose2 pose = Compose(base, o.forward_m, o.left_m, o.facing_rad);
  *x_m = pose.x_m;
  *y_m = pose.y_m;
  *theta_rad = pose.theta_rad;
}

void ExperienceMap::AddLink(uint32_t from, uint32_t to, double time_s,
                            std::optional<double> facing_override, bool loop_closure) {
  const LocalOffset& o = state_.offset;
  Link link;
  link.id = static_cast<uint32_t>(state_.links.size());
  link.from = from;
  link.to = to;
  link.distance_m = std::hypot(o.forward_m, o.left_m);
  link.heading_rad = std::atan2(o.left_m, o.forward_m);
  link.facing_rad = facing_override ? WrapAngle(*facing_override) : o.facing_rad;
  link.duration_s = time_s - state_.offset_start_time_s;
  link.loop_closure = loop_closure;
  state_.experiences[from].link_ids.push_back(link.id);
  state_.experiences[to].link_ids.push_back(link.id);
  state_.links.push_back(link);
}

uint32_t ExperienceMap::CreateExperience(uint32_t template_id, const PoseCellPosition& pose_cells,
                                         double time_s, std::optional<double> compass_heading_rad) {
  Experience e;
  e.id = static_cast<uint32_t>(state_.experiences.size());
  CurrentPose(&e.x_m, &e.y_m, &e.theta_rad);
  e.template_id = template_id;
  e.pose_cells = pose_cells;
  e.time_s = time_s;
  e.compass_heading_rad = compass_heading_rad;
  state_.experiences.push_back(e);
  if (state_.current) {
    const Experience& from = state_.experiences[*state_.current];
    std::optional<double> facing;
    if (compass_heading_rad && from.compass_heading_rad) {
      facing = *compass_heading_rad - *from.compass_heading_rad;
    }
    AddLink(*state_.current, e.id, time_s, facing, false);
  }
  state_.current = e.id;
  state_.offset = LocalOffset();
  state_.offset_start_time_s = time_s;
  return e.id;
}

StatusOr<bool> ExperienceMap::LinkTo(uint32_t id, double time_s,
                                     std::optional<double> compass_heading_rad) {
  if (id >= state_.experiences.size()) {
    return Status::Error("experience map: link to unknown experience " + std::to_string(id));
  }
  bool added = false;
  if (state_.current && *state_.current != id) {
    const uint32_t from = *state_.current;
    bool exists = false;
    for (uint32_t link_id : state_.experiences[from].link_ids) {
      const Link& l = state_.links[link_id];
      if ((l.from == from && l.to == id) || (l.from == id && l.to == from)) exists = true;
    }
    if (!exists) {
      const std::optional<double>& a = state_.experiences[from].compass_heading_rad;
      const std::optional<double>& b = state_.experiences[id].compass_heading_rad;
      std::optional<double> facing;
      if (compass_heading_rad && a && b) facing = *b - *a;
      AddLink(from, id, time_s, facing, true);
      added = true;
    }
  }
  state_.current = id;
  state_.offset = LocalOffset();
  const std::optional<double>& target = state_.experiences[id].compass_heading_rad;
  if (compass_heading_rad && target) {
    state_.offset.facing_rad = WrapAngle(*compass_heading_rad - *target);
  }
  state_.offset_start_time_s = time_s;
  return added;
}

void ExperienceMap::Relax() {
  const double c = options_.relaxation_correction;
  std::vector<Experience>& ex = state_.experiences;
  for (int sweep = 0; sweep < options_.relaxation_sweeps; ++sweep) {
    for (const Link& l : state_.links) {
      Experience& a = ex[l.from];
      Experience& b = ex[l.to];
      // Where the link says b should be, seen from a.
      const double px = a.x_m + l.distance_m * std::cos(a.theta_rad + l.heading_rad);
      const double py = a.y_m + l.distance_m * std::sin(a.theta_rad + l.heading_rad);
      const double ex_m = b.x_m - px;
      const double ey_m = b.y_m - py;
      const double et = WrapAngle(b.theta_rad - (a.theta_rad + l.facing_rad));
      const bool a_fixed = options_.anchor_first_experience && l.from == 0;
      const bool b_fixed = options_.anchor_first_experience && l.to == 0;
      if (!a_fixed) {
        a.x_m += ex_m * c;
        a.y_m += ey_m * c;
        a.theta_rad = WrapAngle(a.theta_rad + et * c);
      }
      if (!b_fixed) {
        b.x_m -= ex_m * c;
        b.y_m -= ey_m * c;
        b.theta_rad = WrapAngle(b.theta_rad - et * c);
      }
    }
  }
}

std::vector<uint32_t> ExperienceMap::ShortestPath(uint32_t from, uint32_t to) const {
  const size_t n = state_.experiences.size();
  if (from >= n || to >= n) return {};
  using Graph =
      boost::adjacency_list<boost::vecS, boost::vecS, boost::undirectedS, boost::no_property,
                            boost::property<boost::edge_weight_t, double>>;
  Graph graph(n);
  for (const Link& l : state_.links) boost::add_edge(l.from, l.to, l.distance_m, graph);
  std::vector<Graph::vertex_descriptor> predecessor(n);
  std::vector<double> distance(n, std::numeric_limits<double>::infinity());
  boost::dijkstra_shortest_paths(
      graph, from, boost::predecessor_map(predecessor.data()).distance_map(distance.data()));
  if (!std::isfinite(distance[to])) return {};
  std::vector<uint32_t> path;
  for (auto v = static_cast<Graph::vertex_descriptor>(to);; v = predecessor[v]) {
    path.push_back(static_cast<uint32_t>(v));
    if (v == from) break;
  }
  return {path.rbegin(), path.rend()};
}

Status ExperienceMap::SetState(State state) {
  // Every id and number is checked before anything is taken over: a restored map is untrusted
  // input, and a dangling id or a NaN would crash or poison the next action.
  auto fail = [](const std::string& what) {
    return Status::Error("experience map state: " + what);
  };
  auto finite = [](double v) { return std::isfinite(v) && std::abs(v) <= kMaxCoordinate; };
  const size_t n = state.experiences.size();
  const size_t n_links = state.links.size();
  for (size_t i = 0; i < n_links; ++i) {
    const Link& l = state.links[i];
    if (l.id != i || l.from >= n || l.to >= n) {
      return fail("link " + std::to_string(i) + " is inconsistent with the experiences");
    }
    if (!finite(l.distance_m) || l.distance_m < 0.0 || !finite(l.heading_rad) ||
        !finite(l.facing_rad) || !finite(l.duration_s)) {
      return fail("link " + std::to_string(i) + " has a non-finite or out-of-range value");
    }
  }
  for (size_t i = 0; i < n; ++i) {
    const Experience& e = state.experiences[i];
    const std::string name = "experience " + std::to_string(i);
    if (e.id != i) return fail(name + " has id " + std::to_string(e.id));
    if (!finite(e.x_m) || !finite(e.y_m) || !finite(e.theta_rad) || !finite(e.time_s) ||
        (e.compass_heading_rad && !finite(*e.compass_heading_rad))) {
      return fail(name + " has a non-finite or out-of-range value");
    }
    for (uint32_t link : e.link_ids) {
      if (link >= n_links || (state.links[link].from != i && state.links[link].to != i)) {
        return fail(name + " lists link " + std::to_string(link) + ", which does not join it");
      }
    }
  }
  if (state.current && *state.current >= n) return fail("current experience does not exist");
  if (!finite(state.offset.forward_m) || !finite(state.offset.left_m) ||
      !finite(state.offset.facing_rad) || !finite(state.offset_start_time_s)) {
    return fail("offset since the current experience is not finite");
  }
  state_ = std::move(state);
  return Status::Ok();
}

}  // namespace ratslam
