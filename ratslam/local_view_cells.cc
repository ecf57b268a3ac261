#include "ratslam/local_view_cells.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "ratslam/experience_map.h"

namespace ratslam {

std::string ToString(ViewMemory memory) {
  return memory == ViewMemory::kFrames ? "frames" : "time";
}

StatusOr<ViewMemory> ViewMemoryFromString(const std::string& name) {
  if (name == "frames") return ViewMemory::kFrames;
  if (name == "time") return ViewMemory::kTime;
  return Status::Error("unknown view memory \"" + name + "\" (frames, time)");
}

bool LocalViewOptions::IsValid(std::string* error) const {
  return schema::CheckFields(*this, error);
}

LocalViewCells::LocalViewCells(const LocalViewOptions& options, int dim_theta_cells)
    : options_(options), dim_theta_cells_(dim_theta_cells) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("LocalViewOptions: " + error);
  if (dim_theta_cells < 1) throw std::invalid_argument("LocalViewCells: dim_theta_cells < 1");
}

double LocalViewCells::DecayAtStartOfFrame(const ViewTemplate& t, uint64_t frame) const {
  // Restores since the stored value are applied lazily, so a frame costs O(1), not O(templates).
  const double elapsed =
      frame > t.decay_frame + 1 ? static_cast<double>(frame - t.decay_frame - 1) : 0.0;
  return std::max(options_.decay_floor, t.decay - options_.decay_restore_per_frame * elapsed);
}

double LocalViewCells::DecayAtTime(const ViewTemplate& t, double time_s) const {
  const double elapsed = std::max(0.0, time_s - t.decay_time_s);
  return std::max(options_.decay_floor, t.decay - options_.decay_restore_per_s * elapsed);
}

void LocalViewCells::SettleForLocalisation(double start_time_s) {
  for (ViewTemplate& t : state_.templates) {
    t.decay = options_.decay_floor;
    t.decay_frame = state_.frame;
    t.decay_time_s = start_time_s;
  }
  settled_templates_ = state_.templates.size();
}

StatusOr<std::optional<Injection>> LocalViewCells::Observe(const ViewDecision& decision,
                                                           const PoseCellPosition& current_pose) {
  const uint64_t frame = ++state_.frame;
  const size_t count = state_.templates.size();
  if (decision.is_new) {
    if (decision.template_id != count) {
      return Status::Error("view decision: new template id " +
                           std::to_string(decision.template_id) + " but " + std::to_string(count) +
                           " templates exist (ids must be consecutive)");
    }
    ViewTemplate t;
    t.id = decision.template_id;
    t.pose_cells = current_pose;
    t.created_time_s = decision.time_s;
    t.decay = options_.decay_floor;
    t.decay_frame = frame;
    t.decay_time_s = decision.time_s;
    state_.templates.push_back(std::move(t));
    return std::optional<Injection>();
  }
  if (decision.template_id >= count) {
    return Status::Error("view decision: template id " + std::to_string(decision.template_id) +
                         " does not exist (" + std::to_string(count) + " templates)");
  }
  ViewTemplate& t = state_.templates[decision.template_id];
  ++t.match_count;
  double decay = 0.0;
  bool recent = false;
  if (options_.memory == ViewMemory::kTime) {
    decay = DecayAtTime(t, decision.time_s) + options_.decay_per_match;
    t.decay = decay;
    t.decay_time_s = std::max(t.decay_time_s, decision.time_s);
    recent = decision.time_s - t.created_time_s < options_.skip_recent_s;
  } else {
    decay = DecayAtStartOfFrame(t, frame) + options_.decay_per_match;
    t.decay = std::max(options_.decay_floor, decay - options_.decay_restore_per_frame);
    recent = decision.template_id + static_cast<uint64_t>(options_.skip_recent_templates) >= count;
  }
  t.decay_frame = frame;
  if (decision.template_id < settled_templates_) recent = false;
  if (recent || !decision.allow_injection) return std::optional<Injection>();
  const double energy = options_.injection_gain *
                        (options_.energy_limit - std::exp(options_.energy_decay_rate * decay)) /
                        options_.energy_limit;
  if (!(energy > 0.0)) return std::optional<Injection>();
  Injection injection;
  injection.position = t.pose_cells;
  injection.position.theta =
      TurnedTheta(t.pose_cells.theta, decision.heading_change_rad, dim_theta_cells_);
  injection.energy = energy;
  return std::optional<Injection>(injection);
}

Status LocalViewCells::SetState(State state) {
  for (size_t i = 0; i < state.templates.size(); ++i) {
    const ViewTemplate& t = state.templates[i];
    const std::string name = "local view state: template " + std::to_string(i);
    if (t.id != i) return Status::Error(name + " has id " + std::to_string(t.id));
    if (!std::isfinite(t.decay) || std::abs(t.decay) > kMaxCoordinate ||
        !std::isfinite(t.created_time_s) || std::abs(t.created_time_s) > kMaxCoordinate ||
        !std::isfinite(t.decay_time_s) || std::abs(t.decay_time_s) > kMaxCoordinate) {
      return Status::Error(name + " has a non-finite or out-of-range decay or time");
    }
    if (t.decay_frame > state.frame) {
      return Status::Error(name + " was last matched after the last frame");
    }
    if (!(t.pose_cells.theta >= 0.0 && t.pose_cells.theta <= dim_theta_cells_)) {
      return Status::Error(name + " has a pose-cell theta outside the ring");
    }
  }
  state_ = std::move(state);
  return Status::Ok();
}

}  // namespace ratslam
