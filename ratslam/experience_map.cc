#include "ratslam/experience_map.h"

#include <algorithm>
#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/dijkstra_shortest_paths.hpp>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>

#include "common/circular.h"
#include "common/geometry.h"

namespace ratslam {

std::string ToString(RelaxationScheme scheme) {
  switch (scheme) {
    case RelaxationScheme::kFull:
      return "full";
    case RelaxationScheme::kIncremental:
      return "incremental";
    case RelaxationScheme::kLeastSquares:
      return "least_squares";
  }
  return "incremental";
}

StatusOr<RelaxationScheme> RelaxationSchemeFromString(const std::string& name) {
  if (name == "full") return RelaxationScheme::kFull;
  if (name == "incremental") return RelaxationScheme::kIncremental;
  if (name == "least_squares") return RelaxationScheme::kLeastSquares;
  return Status::Error("unknown relaxation scheme \"" + name +
                       "\" (full, incremental, least_squares)");
}

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
  Pose2 base{0.0, 0.0, options_.initial_heading_rad};
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
  relax_links_.push_back(ToRelaxLink(link));
  // The newest id: the region stays ascending. Least squares waits for a loop closure.
  const bool pending =
      options_.relaxation_scheme == RelaxationScheme::kIncremental ||
      (options_.relaxation_scheme == RelaxationScheme::kLeastSquares && loop_closure);
  if (pending) state_.relaxation_pending_links.push_back(link.id);
  in_region_.push_back(pending ? 1 : 0);
  if (outside_.size() < state_.experiences.size()) outside_.resize(state_.experiences.size(), 0);
  if (!pending) {
    ++outside_[from];
    ++outside_[to];
  }
  if (options_.relaxation_scheme == RelaxationScheme::kLeastSquares && !loop_closure) {
    // `to` is new, a leaf: the least-squares optimum satisfies its one link exactly. Its
    // position already does; its facing takes the link's (the compass difference when there is
    // a compass), so dead reckoning goes on from the corrected heading.
    Experience& b = state_.experiences[to];
    b.theta_rad = WrapAngle(state_.experiences[from].theta_rad + link.facing_rad);
  }
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

bool ExperienceMap::Linked(uint32_t a, uint32_t b) const {
  for (uint32_t link_id : state_.experiences[a].link_ids) {
    const Link& l = state_.links[link_id];
    if ((l.from == a && l.to == b) || (l.from == b && l.to == a)) return true;
  }
  return false;
}

StatusOr<bool> ExperienceMap::AddConstraint(uint32_t from, uint32_t to, const Pose2& relative,
                                            double time_s) {
  if (from >= state_.experiences.size() || to >= state_.experiences.size()) {
    return Status::Error("experience map: constraint between unknown experiences " +
                         std::to_string(from) + " and " + std::to_string(to));
  }
  if (!std::isfinite(relative.x_m) || !std::isfinite(relative.y_m) ||
      !std::isfinite(relative.theta_rad) || !std::isfinite(time_s)) {
    return Status::Error("experience map: constraint with a non-finite pose or time");
  }
  if (from == to || Linked(from, to)) return false;
  // AddLink measures the link from the odometry offset; give it the constraint instead.
  const LocalOffset odometry = state_.offset;
  const double start = state_.offset_start_time_s;
  state_.offset = {relative.x_m, relative.y_m, WrapAngle(relative.theta_rad)};
  state_.offset_start_time_s = time_s;
  const std::optional<double>& a = state_.experiences[from].compass_heading_rad;
  const std::optional<double>& b = state_.experiences[to].compass_heading_rad;
  std::optional<double> facing;
  if (a && b) facing = *b - *a;
  AddLink(from, to, time_s, facing, true);
  state_.links.back().wifi_sequence = true;
  state_.offset = odometry;
  state_.offset_start_time_s = start;
  return true;
}

StatusOr<bool> ExperienceMap::LinkTo(uint32_t id, double time_s,
                                     std::optional<double> compass_heading_rad) {
  if (id >= state_.experiences.size()) {
    return Status::Error("experience map: link to unknown experience " + std::to_string(id));
  }
  bool added = false;
  if (state_.current && *state_.current != id) {
    const uint32_t from = *state_.current;
    if (!Linked(from, id)) {
      const std::optional<double>& a = state_.experiences[from].compass_heading_rad;
      const std::optional<double>& b = state_.experiences[id].compass_heading_rad;
      std::optional<double> facing;
      if (compass_heading_rad && a && b) facing = *b - *a;
      AddLink(from, id, time_s, facing, true);
      added = true;
    }
  }
  MoveTo(id, time_s, compass_heading_rad);
  return added;
}

void ExperienceMap::MoveTo(uint32_t id, double time_s, std::optional<double> compass_heading_rad) {
  state_.current = id;
  state_.offset = LocalOffset();
  const std::optional<double>& target = state_.experiences[id].compass_heading_rad;
  if (compass_heading_rad && target) {
    state_.offset.facing_rad = WrapAngle(*compass_heading_rad - *target);
  }
  state_.offset_start_time_s = time_s;
}

void ExperienceMap::Relax() {
  switch (options_.relaxation_scheme) {
    case RelaxationScheme::kFull:
      RelaxFull();
      break;
    case RelaxationScheme::kIncremental:
      RelaxIncremental();
      break;
    case RelaxationScheme::kLeastSquares:
      RelaxLeastSquares();
      break;
  }
}

void ExperienceMap::RelaxLeastSquares() {
  if (state_.relaxation_pending_links.empty()) return;
  ++least_squares_runs_;
  // The first experience stays put, as with anchor_first_experience: the gauge.
  if (!OptimisePoseGraph(&state_.experiences, state_.links, options_.Noise()).ok()) {
    ++least_squares_failures_;
    return;  // the map is unchanged; the pending closure is retried at the next action
  }
  for (uint32_t l : state_.relaxation_pending_links) LeaveRegion(l);
  state_.relaxation_pending_links.clear();
}

template <typename Pose>
inline ExperienceMap::EndMotion ExperienceMap::CorrectLink(Pose& a, Pose& b, double distance_m,
                                                           double facing_rad, double cos_direction,
                                                           double sin_direction, double c,
                                                           bool a_fixed, bool b_fixed) {
  // Where the link says b should be, seen from a.
  const double px = a.x_m + distance_m * cos_direction;
  const double py = a.y_m + distance_m * sin_direction;
  const double ex_m = b.x_m - px;
  const double ey_m = b.y_m - py;
  const double et = WrapAngleNear(b.theta_rad - (a.theta_rad + facing_rad));
  const double moved_m = (std::abs(ex_m) + std::abs(ey_m)) * c;
  const double moved_rad = std::abs(et) * c;
  EndMotion motion{0.0, 0.0, 0.0, 0.0};
  if (!a_fixed) {
    a.x_m += ex_m * c;
    a.y_m += ey_m * c;
    a.theta_rad = WrapAngleNear(a.theta_rad + et * c);
    motion.a_m = moved_m;
    motion.a_rad = moved_rad;
  }
  if (!b_fixed) {
    b.x_m -= ex_m * c;
    b.y_m -= ey_m * c;
    b.theta_rad = WrapAngleNear(b.theta_rad - et * c);
    motion.b_m = moved_m;
    motion.b_rad = moved_rad;
  }
  return motion;
}

void ExperienceMap::UpdateLink(const Link& l, double cos_direction, double sin_direction) {
  const bool anchor = options_.anchor_first_experience;
  CorrectLink(state_.experiences[l.from], state_.experiences[l.to], l.distance_m, l.facing_rad,
              cos_direction, sin_direction, options_.relaxation_correction, anchor && l.from == 0,
              anchor && l.to == 0);
}

void ExperienceMap::RelaxFull() {
  // OpenRatSLAM's scheme, bit for bit as before the incremental one existed (WrapAngleNear equals
  // WrapAngle): the reference the incremental scheme is measured against.
  for (uint32_t l : state_.relaxation_pending_links) LeaveRegion(l);
  state_.relaxation_pending_links.clear();
  const std::vector<Experience>& ex = state_.experiences;
  for (int sweep = 0; sweep < options_.relaxation_sweeps; ++sweep) {
    for (const Link& l : state_.links) {
      const double direction = ex[l.from].theta_rad + l.heading_rad;
      UpdateLink(l, std::cos(direction), std::sin(direction));
    }
    link_updates_ += state_.links.size();
  }
}

ExperienceMap::RelaxLink ExperienceMap::ToRelaxLink(const Link& l) {
  return {l.from,      l.to, l.distance_m, std::cos(l.heading_rad), std::sin(l.heading_rad),
          l.facing_rad};
}

void ExperienceMap::LoadPose(uint32_t id) {
  RelaxPose& p = relax_poses_[id];
  p.call = call_;
  const Experience& e = state_.experiences[id];
  p.x_m = e.x_m;
  p.y_m = e.y_m;
  p.theta_rad = e.theta_rad;
  if (experience_trig_rad_[id] != e.theta_rad) {  // NaN compares unequal: computed the first time
    ::sincos(e.theta_rad, &experience_sin_[id], &experience_cos_[id]);  // glibc: both at once
    experience_trig_rad_[id] = e.theta_rad;
  }
  p.cos_theta = experience_cos_[id];
  p.sin_theta = experience_sin_[id];
  p.trig_theta_rad = e.theta_rad;
  loaded_.push_back(id);
}

inline ExperienceMap::RelaxPose& ExperienceMap::Touch(uint32_t id) {
  RelaxPose& p = relax_poses_[id];
  if (p.pass == pass_) return p;
  if (p.call != call_) LoadPose(id);  // first touch in this call
  // A pass reads each experience's rotation once, at its first touch: the cos and sin of the
  // last pass turned by what the experience rotated since (angle sum formulas), so a pass calls
  // no trig function per experience.
  if (p.theta_rad != p.trig_theta_rad) {
    double sin_turn, cos_turn;
    SinCosOfSmallAngle(WrapAngleNear(p.theta_rad - p.trig_theta_rad), &sin_turn, &cos_turn);
    const double c = p.cos_theta, s = p.sin_theta;
    p.cos_theta = c * cos_turn - s * sin_turn;
    p.sin_theta = s * cos_turn + c * sin_turn;
    p.trig_theta_rad = p.theta_rad;
  }
  p.pass = pass_;
  p.start_x_m = p.x_m;
  p.start_y_m = p.y_m;
  p.start_theta_rad = p.theta_rad;
  touched_.push_back(id);
  return p;
}

inline ExperienceMap::EndMotion ExperienceMap::UpdateRelaxLink(const RelaxLink& l, RelaxPose& a,
                                                               RelaxPose& b, bool a_fixed,
                                                               bool b_fixed) const {
  // The link's direction: a's rotation (as the pass first read it) plus the link's heading.
  const double cos_direction = a.cos_theta * l.cos_heading - a.sin_theta * l.sin_heading;
  const double sin_direction = a.sin_theta * l.cos_heading + a.cos_theta * l.sin_heading;
  return CorrectLink(a, b, l.distance_m, l.facing_rad, cos_direction, sin_direction,
                     options_.relaxation_correction, a_fixed, b_fixed);
}

void ExperienceMap::LeaveRegion(uint32_t link) {
  in_region_[link] = 0;
  ++outside_[relax_links_[link].from];
  ++outside_[relax_links_[link].to];
}

bool ExperienceMap::GrowRegion(uint32_t id, uint32_t above, bool this_pass) {
  if (outside_[id] == 0) return false;  // all its links are in the region already
  bool grown = false;
  const size_t cap = static_cast<size_t>(options_.relaxation_max_region_links);
  for (uint32_t k : state_.experiences[id].link_ids) {
    if (k < above || in_region_[k]) continue;
    if (cap > 0 && state_.relaxation_pending_links.size() + grown_.size() >= cap) {
      capped_this_pass_ = true;
      break;
    }
    in_region_[k] = 1;
    --outside_[relax_links_[k].from];
    --outside_[relax_links_[k].to];
    grown_.push_back(k);
    grown = true;
    if (this_pass) {
      ahead_.push_back(k);
      std::push_heap(ahead_.begin(), ahead_.end(), std::greater<>());
    }
  }
  return grown;
}

void ExperienceMap::RelaxIncremental() {
  std::vector<uint32_t>& region = state_.relaxation_pending_links;
  if (region.empty() || options_.relaxation_sweeps == 0) return;
  const size_t n = state_.experiences.size();
  relax_poses_.resize(n);
  experience_cos_.resize(n);
  experience_sin_.resize(n);
  experience_trig_rad_.resize(n, std::numeric_limits<double>::quiet_NaN());
  ++call_;
  loaded_.clear();
  const double tolerance_m = options_.relaxation_tolerance_m;
  const double tolerance_rad = options_.relaxation_tolerance_rad;
  const bool anchor = options_.anchor_first_experience;
  for (int sweep = 0; sweep < options_.relaxation_sweeps && !region.empty(); ++sweep) {
    ++pass_;
    capped_this_pass_ = false;
    touched_.clear();
    grown_.clear();
    ahead_.clear();
    bool grown = false;
    // The region in ascending order, merged with the links that join it during the pass (all
    // above the link being updated, kept in a min-heap).
    size_t next = 0;
    while (next < region.size() || !ahead_.empty()) {
      uint32_t l;
      if (!ahead_.empty() && (next == region.size() || ahead_.front() < region[next])) {
        std::pop_heap(ahead_.begin(), ahead_.end(), std::greater<>());
        l = ahead_.back();
        ahead_.pop_back();
      } else {
        l = region[next++];
      }
      const RelaxLink& link = relax_links_[l];
      RelaxPose& a = Touch(link.from);
      RelaxPose& b = Touch(link.to);
      const EndMotion motion =
          UpdateRelaxLink(link, a, b, anchor && link.from == 0, anchor && link.to == 0);
      ++link_updates_;
      // A large step of an end reaches its links further on in this same pass, as in a full
      // pass; links before it join when the pass has moved the end.
      if ((motion.a_m > tolerance_m || motion.a_rad > tolerance_rad) && outside_[link.from] > 0) {
        grown |= GrowRegion(link.from, l + 1, true);
      }
      if ((motion.b_m > tolerance_m || motion.b_rad > tolerance_rad) && outside_[link.to] > 0) {
        grown |= GrowRegion(link.to, l + 1, true);
      }
    }
    // Single updates in an inconsistent loop swing back and forth for ever (cyclic projections
    // reach a limit cycle), but the poses at the end of a pass over a fixed set of links
    // converge. So the region only grows, by the links of experiences the pass moved on net,
    // and is done when a pass moves nothing on net by more than the tolerances.
    bool settled = true;
    for (uint32_t id : touched_) {
      const RelaxPose& p = relax_poses_[id];
      if (std::abs(p.x_m - p.start_x_m) + std::abs(p.y_m - p.start_y_m) > tolerance_m ||
          std::abs(WrapAngleNear(p.theta_rad - p.start_theta_rad)) > tolerance_rad) {
        settled = false;
        grown |= GrowRegion(id, 0, false);
      }
    }
    if (capped_this_pass_) ++capped_passes_;
    if (settled && !grown) {
      for (uint32_t l : region) LeaveRegion(l);
      region.clear();
      break;
    }
    if (!grown_.empty()) {
      const size_t old_size = region.size();
      region.insert(region.end(), grown_.begin(), grown_.end());
      std::sort(region.begin() + old_size, region.end());
      std::inplace_merge(region.begin(), region.begin() + old_size, region.end());
    }
    const size_t cap = static_cast<size_t>(options_.relaxation_max_region_links);
    if (cap > 0 && region.size() > cap) TrimRegion(cap);
  }
  for (uint32_t id : loaded_) {
    const RelaxPose& p = relax_poses_[id];
    Experience& e = state_.experiences[id];
    e.x_m = p.x_m;
    e.y_m = p.y_m;
    e.theta_rad = p.theta_rad;
  }
}

void ExperienceMap::TrimRegion(size_t cap) {
  // New links joined a region at its cap: the links whose ends this pass moved least on net
  // (in units of the tolerances) leave it, ties by the lower id, so the region keeps its
  // unsettled part.
  if (!capped_this_pass_) ++capped_passes_;
  capped_this_pass_ = true;
  std::vector<uint32_t>& region = state_.relaxation_pending_links;
  auto net = [&](uint32_t id) {
    const RelaxPose& p = relax_poses_[id];
    if (p.call != call_ || p.pass != pass_) return 0.0;
    return std::max((std::abs(p.x_m - p.start_x_m) + std::abs(p.y_m - p.start_y_m)) /
                        options_.relaxation_tolerance_m,
                    std::abs(WrapAngleNear(p.theta_rad - p.start_theta_rad)) /
                        options_.relaxation_tolerance_rad);
  };
  std::vector<std::pair<double, uint32_t>> ranked;
  ranked.reserve(region.size());
  for (uint32_t l : region) {
    const RelaxLink& link = relax_links_[l];
    ranked.emplace_back(std::max(net(link.from), net(link.to)), l);
  }
  // Largest movement first, then the higher id: the first `cap` stay.
  std::nth_element(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(cap), ranked.end(),
                   std::greater<>());
  for (size_t i = cap; i < ranked.size(); ++i) LeaveRegion(ranked[i].second);
  region.clear();
  for (size_t i = 0; i < cap; ++i) region.push_back(ranked[i].second);
  std::sort(region.begin(), region.end());
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

bool ExperienceMap::JoinedWithin(uint32_t from, uint32_t to, double within_m) const {
  const size_t n = state_.experiences.size();
  if (from >= n || to >= n) return false;
  // Dijkstra bounded by within_m: around a closure the region is a few links.
  std::map<uint32_t, double> reached{{from, 0.0}};
  std::set<std::pair<double, uint32_t>> frontier{{0.0, from}};
  while (!frontier.empty()) {
    const auto [d, u] = *frontier.begin();
    frontier.erase(frontier.begin());
    if (u == to) return true;
    for (uint32_t link_id : state_.experiences[u].link_ids) {
      const Link& l = state_.links[link_id];
      if (l.wifi_sequence) continue;
      const uint32_t v = l.from == u ? l.to : l.from;
      const double dv = d + l.distance_m;
      if (dv >= within_m) continue;
      auto it = reached.find(v);
      if (it != reached.end() && it->second <= dv) continue;
      if (it != reached.end()) frontier.erase({it->second, v});
      reached[v] = dv;
      frontier.insert({dv, v});
    }
  }
  return false;
}

Status ExperienceMap::SetState(State state) {
  // Every id and number is checked before anything is taken over: a restored map is untrusted
  // input, and a dangling id or a NaN would crash or poison the next action.
  RATSLAM_RETURN_IF_ERROR(ValidateState(state));
  const size_t n_links = state.links.size();
  state_ = std::move(state);
  relax_links_.clear();
  for (const Link& l : state_.links) relax_links_.push_back(ToRelaxLink(l));
  in_region_.assign(n_links, 0);
  for (uint32_t l : state_.relaxation_pending_links) in_region_[l] = 1;
  outside_.assign(state_.experiences.size(), 0);
  for (size_t i = 0; i < n_links; ++i) {
    if (in_region_[i]) continue;
    ++outside_[state_.links[i].from];
    ++outside_[state_.links[i].to];
  }
  return Status::Ok();
}

Status ExperienceMap::ValidateState(const State& state) {
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
  for (size_t i = 0; i < state.relaxation_pending_links.size(); ++i) {
    const uint32_t l = state.relaxation_pending_links[i];
    if (l >= n_links || (i > 0 && l <= state.relaxation_pending_links[i - 1])) {
      return fail("links being relaxed are not ascending link ids");
    }
  }
  if (!finite(state.offset.forward_m) || !finite(state.offset.left_m) ||
      !finite(state.offset.facing_rad) || !finite(state.offset_start_time_s)) {
    return fail("offset since the current experience is not finite");
  }
  return Status::Ok();
}

}  // namespace ratslam
