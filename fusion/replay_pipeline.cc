#include "fusion/replay_pipeline.h"

#include <cmath>
#include <stdexcept>

#include "common/circular.h"
#include "common/geometry.h"

namespace ratslam {

bool PipelineOptions::IsValid(std::string* error) const {
  std::string inner;
  auto check = [&](bool ok, const char* section) {
    if (!ok && error) *error = std::string(section) + "." + inner;
    return ok;
  };
  return check(sensors.classic_camera.IsValid(&inner), "camera") &&
         check(sensors.fused.IsValid(&inner), "fused") &&
         check(sensors.camera_12x9.IsValid(&inner), "camera_12x9") &&
         check(sensors.wifi.IsValid(&inner), "wifi") && check(pdr.IsValid(&inner), "pdr") &&
         check(visual_odometry.IsValid(&inner), "visual_odometry") && ratslam.IsValid(error) &&
         sensors.fabmap.IsValid(error) && check(evaluation.IsValid(&inner), "evaluation");
}

namespace {

bool Bounded(double v) { return std::isfinite(v) && std::abs(v) <= kMaxCoordinate; }

// The pipeline's own records point into the spine's templates and experiences; the outputs
// follow those ids, so every one is checked before a restored state is taken over.
Status CheckRecords(const ReplayPipeline::State& state) {
  const auto templates = static_cast<int64_t>(state.ratslam.local_view.templates.size());
  const auto experiences = static_cast<int64_t>(state.ratslam.experience_map.experiences.size());
  auto experience_ok = [experiences](int64_t id) { return id >= -1 && id < experiences; };
  for (size_t i = 0; i < state.trajectory.size(); ++i) {
    const TrajectoryRecord& t = state.trajectory[i];
    if (!experience_ok(t.experience_id)) {
      return Status::Error("saved map: trajectory record " + std::to_string(i) +
                           " refers to an experience that does not exist");
    }
    if (!Bounded(t.time_s) || !Bounded(t.offset.forward_m) || !Bounded(t.offset.left_m) ||
        !Bounded(t.offset.facing_rad) || !Bounded(t.odometry_x_m) || !Bounded(t.odometry_y_m) ||
        !Bounded(t.odometry_theta_rad)) {
      return Status::Error("saved map: trajectory record " + std::to_string(i) +
                           " has a non-finite or out-of-range value");
    }
  }
  for (size_t i = 0; i < state.frames.size(); ++i) {
    const FrameRecord& f = state.frames[i];
    if (f.template_id >= templates || !experience_ok(f.experience_id) || !Bounded(f.time_s)) {
      return Status::Error("saved map: frame record " + std::to_string(i) +
                           " refers to a template or experience that does not exist");
    }
  }
  if (!Bounded(state.last_odometry_time_s) || !Bounded(state.odometry_x_m) ||
      !Bounded(state.odometry_y_m) || !Bounded(state.odometry_theta_rad)) {
    return Status::Error("saved map: dead-reckoned pose is not finite");
  }
  return Status::Ok();
}

const PipelineOptions& Validated(const PipelineOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("PipelineOptions: " + error);
  return options;
}
}  // namespace

ReplayPipeline::ReplayPipeline(const PipelineOptions& options, const Dataset& dataset,
                               ImageLoader* images, std::shared_ptr<const FabmapResources> fabmap)
    : options_(Validated(options)),
      dataset_(dataset),
      images_(images),
      events_(MergeEvents(dataset)),
      slam_(std::make_unique<Ratslam>(options.ratslam)),
      fabmap_(std::move(fabmap)),
      front_end_(CreateFrontEnd(options.sensors, fabmap_)) {
  state_.events_total = events_.size();
}

Status ReplayPipeline::Run(const ReplayControl& control) {
  ReplayProgress progress;
  progress.events_total = events_.size();
  while (state_.next_event < events_.size()) {
    if (control.stop_requested && control.stop_requested->load()) break;
    const Event& event = events_[state_.next_event];
    if (event.time_s > control.until_time_s) break;
    Status status;
    switch (event.type) {
      case EventType::kOdometry:
        status = HandleOdometry(event);
        break;
      case EventType::kImage:
        status = HandleImage(event);
        break;
      case EventType::kWifi:
        status = HandleWifi(event);
        break;
      case EventType::kCompass: {
        const CompassRow& row = dataset_.compass[event.index];
        ++state_.compass_readings_seen;
        front_end_->OnCompass(row.time_s, row.heading_rad);
        slam_->SetCompassHeading(front_end_->CompassHeading());
        break;
      }
    }
    if (!status.ok()) return status;
    ++state_.next_event;
    if (control.checkpoint && control.checkpoint_every > 0 &&
        (state_.next_event % control.checkpoint_every == 0 || finished())) {
      RATSLAM_RETURN_IF_ERROR(control.checkpoint(*this));
    }
    if (control.progress && (state_.next_event % control.progress_every == 0 || finished())) {
      progress.events_done = state_.next_event;
      progress.data_time_s = event.time_s;
      control.progress(progress);
    }
  }
  return Status::Ok();
}

Status ReplayPipeline::HandleOdometry(const Event& event) {
  const OdometryRow& row = dataset_.odometry[event.index];
  const double dt = state_.have_odometry ? row.time_s - state_.last_odometry_time_s : 0.0;
  state_.have_odometry = true;
  state_.last_odometry_time_s = row.time_s;
  OdometryStep step;
  step.time_s = row.time_s;
  step.forward_m = row.forward_speed_m_per_s * dt;
  step.rotation_rad = row.turn_rate_rad_per_s * dt;
  StatusOr<ActionKind> action = slam_->OnOdometry(step);
  if (!action.ok()) return action.status();

  // Raw dead reckoning with the same midpoint rule as the experience map.
  Pose2 odometry{state_.odometry_x_m, state_.odometry_y_m, state_.odometry_theta_rad};
  AdvanceMidpoint(&odometry, step.forward_m, step.rotation_rad);
  state_.odometry_x_m = odometry.x_m;
  state_.odometry_y_m = odometry.y_m;
  state_.odometry_theta_rad = odometry.theta_rad;

  TrajectoryRecord record;
  record.time_s = row.time_s;
  const ExperienceMap& map = slam_->experience_map();
  record.experience_id = map.current() ? static_cast<int64_t>(*map.current()) : -1;
  record.offset = map.offset();
  record.odometry_x_m = state_.odometry_x_m;
  record.odometry_y_m = state_.odometry_y_m;
  record.odometry_theta_rad = state_.odometry_theta_rad;
  state_.trajectory.push_back(record);
  return Status::Ok();
}

Status ReplayPipeline::HandleImage(const Event& event) {
  if (!front_end_->WantsImages()) {
    ++state_.images_skipped;
    return Status::Ok();
  }
  const ImageRow& row = dataset_.images[event.index];
  const std::string where = "images.csv:" + std::to_string(row.line);
  StatusOr<GrayImage> image = images_->Load(dataset_.ImagePath(row));
  if (!image.ok()) return image.status().WithContext(where);
  StatusOr<std::optional<FrameDecision>> decision = front_end_->OnImage(row.time_s, image.value());
  if (!decision.ok()) return decision.status().WithContext(where + ": " + row.file);
  return decision.value() ? Apply(*decision.value()) : Status::Ok();
}

Status ReplayPipeline::HandleWifi(const Event& event) {
  ++state_.wifi_scans_seen;
  StatusOr<std::optional<FrameDecision>> decision = front_end_->OnWifi(dataset_.wifi[event.index]);
  if (!decision.ok()) return decision.status();
  return decision.value() ? Apply(*decision.value()) : Status::Ok();
}

Status ReplayPipeline::Apply(const FrameDecision& decision) {
  RATSLAM_RETURN_IF_ERROR(slam_->OnView(decision.view));
  FrameRecord frame;
  frame.time_s = decision.view.time_s;
  frame.template_id = decision.view.template_id;
  frame.is_new = decision.view.is_new;
  frame.source = decision.source;
  frame.recent = decision.recent;
  const auto current = slam_->experience_map().current();
  frame.experience_id = current ? static_cast<int64_t>(*current) : -1;
  state_.frames.push_back(frame);
  return Status::Ok();
}

ReplayPipeline::State ReplayPipeline::Snapshot() const {
  State snapshot = state_;
  snapshot.ratslam = slam_->GetState();
  snapshot.front_end = front_end_->EncodeState();
  return snapshot;
}

Status ReplayPipeline::Restore(const State& state) {
  if (state.events_total != events_.size()) {
    return Status::Error("saved map was made from a data set with " +
                         std::to_string(state.events_total) + " events; this one has " +
                         std::to_string(events_.size()));
  }
  if (state.next_event > events_.size()) return Status::Error("saved map is past the data set");
  RATSLAM_RETURN_IF_ERROR(CheckRecords(state));
  auto slam = std::make_unique<Ratslam>(options_.ratslam);
  RATSLAM_RETURN_IF_ERROR(slam->SetState(state.ratslam));
  std::unique_ptr<FrontEnd> front_end = CreateFrontEnd(options_.sensors, fabmap_);
  RATSLAM_RETURN_IF_ERROR(front_end->DecodeState(state.front_end));
  if (front_end->size() != slam->local_view().size()) {
    return Status::Error("saved map: front-end templates and local view cells differ in number");
  }
  slam_ = std::move(slam);
  front_end_ = std::move(front_end);
  state_ = state;
  state_.ratslam = {};
  state_.front_end.clear();
  return Status::Ok();
}

}  // namespace ratslam
