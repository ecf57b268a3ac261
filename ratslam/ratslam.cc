#include "ratslam/ratslam.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace ratslam {

bool ActionOptions::IsValid(std::string* error) const { return schema::CheckFields(*this, error); }

bool RatslamOptions::IsValid(std::string* error) const {
  std::string inner;
  auto check = [&](bool ok, const char* section) {
    if (!ok && error) *error = std::string(section) + "." + inner;
    return ok;
  };
  return check(pose_cells.IsValid(&inner), "pose_cells") &&
         check(local_view.IsValid(&inner), "local_view") &&
         check(experience_map.IsValid(&inner), "experience_map") &&
         check(action.IsValid(&inner), "action");
}

namespace {
const RatslamOptions& Validated(const RatslamOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("RatslamOptions: " + error);
  return options;
}
}  // namespace

Ratslam::Ratslam(const RatslamOptions& options)
    : options_(Validated(options)),
      pose_cells_(options.pose_cells),
      local_view_(options.local_view, options.pose_cells.dim_theta_cells),
      experience_map_(options.experience_map) {}

Status Ratslam::OnView(const ViewDecision& decision) {
  StatusOr<std::optional<Injection>> injection =
      local_view_.Observe(decision, pose_cells_.BestPosition());
  if (!injection.ok()) return injection.status();
  ++counters_.view_frames;
  current_template_ = decision.template_id;
  if (frozen_templates_ && decision.template_id >= *frozen_templates_) {
    current_template_.reset();
    ++localisation_counters_.unmapped_views;
    return Status::Ok();
  }
  if (frozen_templates_ && relocalise_after_m_ && Lost(*relocalise_after_m_)) {
    // Lost on a frozen map, and viewing one of its templates: back to its experience at once.
    const ViewTemplate& view = local_view_.at(decision.template_id);
    const PoseCellPosition best = pose_cells_.BestPosition();
    std::optional<uint32_t> nearest;
    double nearest_distance = std::numeric_limits<double>::infinity();
    for (uint32_t id : view.experience_ids) {
      const double d =
          PoseCellDistance(experience_map_.experience(id).pose_cells, best,
                           options_.pose_cells.dim_xy_cells, options_.pose_cells.dim_theta_cells);
      if (d < nearest_distance) nearest_distance = d, nearest = id;
    }
    if (nearest) {
      // Facing as the view says (a compass's change since the template), as an injection would.
      PoseCellPosition at = experience_map_.experience(*nearest).pose_cells;
      at.theta =
          TurnedTheta(at.theta, decision.heading_change_rad, options_.pose_cells.dim_theta_cells);
      pose_cells_.Reset(at);
      experience_map_.MoveTo(*nearest, decision.time_s, compass_heading_rad_);
      ++localisation_counters_.recognitions;
      ++localisation_counters_.relocalisations;
      return Status::Ok();
    }
  }
  if (injection.value()) {
    StageTimer timer(stage_times_ ? &stage_times_->pose_cells_s : nullptr);
    pose_cells_.Inject(injection.value()->position, injection.value()->energy);
    ++counters_.injections;
  }
  return Status::Ok();
}

bool Ratslam::Lost(double after_m) const {
  const LocalOffset& o = experience_map_.offset();
  return !experience_map_.current() || std::hypot(o.forward_m, o.left_m) > after_m;
}

StatusOr<ActionKind> Ratslam::OnOdometry(const OdometryStep& step) {
  if (!std::isfinite(step.forward_m) || !std::isfinite(step.rotation_rad)) {
    return Status::Error("odometry step at t=" + std::to_string(step.time_s) + " is not finite");
  }
  ++counters_.odometry_steps;
  {
    StageTimer timer(stage_times_ ? &stage_times_->pose_cells_s : nullptr);
    pose_cells_.Step(step.forward_m, step.rotation_rad);
  }
  StageTimer timer(stage_times_ ? &stage_times_->experience_map_s : nullptr);
  experience_map_.Integrate(step.forward_m, step.rotation_rad);
  return Act(step.time_s);
}

void Ratslam::FreezeMap(double start_time_s, std::optional<double> relocalise_after_m) {
  frozen_templates_ = local_view_.size();
  relocalise_after_m_ = relocalise_after_m;
  local_view_.SettleForLocalisation(start_time_s);
  current_template_.reset();
  experience_map_.Forget();
}

StatusOr<ActionKind> Ratslam::Act(double time_s) {
  if (!current_template_) return ActionKind::kNone;
  const PoseCellPosition best = pose_cells_.BestPosition();
  ViewTemplate& view = local_view_.at(*current_template_);
  const int dim_xy = options_.pose_cells.dim_xy_cells;
  const int dim_theta = options_.pose_cells.dim_theta_cells;

  std::optional<uint32_t> nearest;
  double nearest_distance = std::numeric_limits<double>::infinity();
  int candidates = 0;
  for (uint32_t id : view.experience_ids) {
    PoseCellPosition stored = experience_map_.experience(id).pose_cells;
    if (!options_.action.match_heading) stored.theta = best.theta;
    const double d = PoseCellDistance(stored, best, dim_xy, dim_theta);
    if (d < options_.action.match_distance_cells) ++candidates;
    if (d < nearest_distance) {
      nearest_distance = d;
      nearest = id;
    }
  }

  if (frozen_templates_) {
    if (!nearest || nearest_distance >= options_.action.match_distance_cells ||
        experience_map_.current() == nearest) {
      return ActionKind::kNone;
    }
    experience_map_.MoveTo(*nearest, time_s, compass_heading_rad_);
    ++localisation_counters_.recognitions;
    return ActionKind::kRecognised;
  }
  ActionKind action = ActionKind::kNone;
  if (!nearest || nearest_distance >= options_.action.match_distance_cells) {
    const uint32_t id =
        experience_map_.CreateExperience(*current_template_, best, time_s, compass_heading_rad_);
    view.experience_ids.push_back(id);
    action = ActionKind::kCreatedExperience;
  } else if (experience_map_.current() == nearest) {
    return ActionKind::kNone;
  } else if (candidates > 1 && options_.action.refuse_ambiguous_links) {
    ++counters_.refused_ambiguous;
    return ActionKind::kRefusedAmbiguous;
  } else {
    StatusOr<bool> linked = experience_map_.LinkTo(*nearest, time_s, compass_heading_rad_);
    if (!linked.ok()) return linked.status();
    if (linked.value()) ++counters_.loop_closures;
    action = ActionKind::kLinkedExisting;
  }
  experience_map_.Relax();
  return action;
}

Ratslam::State Ratslam::GetState() const {
  return {pose_cells_.GetState(), local_view_.state(), experience_map_.state(),
          current_template_,      counters_,           compass_heading_rad_};
}

namespace {

// The cross-references between the components that none of them can check alone.
Status CheckCrossReferences(const Ratslam::State& state, const PoseCellOptions& grid) {
  const auto& templates = state.local_view.templates;
  const auto& experiences = state.experience_map.experiences;
  auto on_grid = [&grid](const PoseCellPosition& p) {
    return p.x >= 0.0 && p.x <= grid.dim_xy_cells && p.y >= 0.0 && p.y <= grid.dim_xy_cells &&
           p.theta >= 0.0 && p.theta <= grid.dim_theta_cells;
  };
  for (const ViewTemplate& t : templates) {
    const std::string name = "state: template " + std::to_string(t.id);
    if (!on_grid(t.pose_cells)) return Status::Error(name + " lies outside the pose-cell grid");
    for (uint32_t id : t.experience_ids) {
      if (id >= experiences.size() || experiences[id].template_id != t.id) {
        return Status::Error(name + " lists experience " + std::to_string(id) +
                             ", which does not exist or belongs to another template");
      }
    }
  }
  for (const Experience& e : experiences) {
    const std::string name = "state: experience " + std::to_string(e.id);
    if (e.template_id >= templates.size()) {
      return Status::Error(name + " refers to a template that does not exist");
    }
    if (!on_grid(e.pose_cells)) return Status::Error(name + " lies outside the pose-cell grid");
  }
  if (state.current_template && *state.current_template >= templates.size()) {
    return Status::Error("state: current template does not exist");
  }
  if (state.compass_heading_rad && !std::isfinite(*state.compass_heading_rad)) {
    return Status::Error("state: compass heading is not finite");
  }
  return Status::Ok();
}

}  // namespace

Status Ratslam::SetState(const State& state) {
  RATSLAM_RETURN_IF_ERROR(CheckCrossReferences(state, options_.pose_cells));
  // All or nothing: restore into fresh components, then swap them in.
  PoseCellNetwork pose_cells(options_.pose_cells);
  LocalViewCells local_view(options_.local_view, options_.pose_cells.dim_theta_cells);
  ExperienceMap experience_map(options_.experience_map);
  RATSLAM_RETURN_IF_ERROR(pose_cells.SetState(state.pose_cells));
  RATSLAM_RETURN_IF_ERROR(local_view.SetState(state.local_view));
  RATSLAM_RETURN_IF_ERROR(experience_map.SetState(state.experience_map));
  pose_cells_ = std::move(pose_cells);
  local_view_ = std::move(local_view);
  experience_map_ = std::move(experience_map);
  current_template_ = state.current_template;
  counters_ = state.counters;
  compass_heading_rad_ = state.compass_heading_rad;
  return Status::Ok();
}

}  // namespace ratslam
