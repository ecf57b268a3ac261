#include "fusion/replay_pipeline.h"

#include <cmath>
#include <stdexcept>

#include "ratslam/circular.h"

namespace ratslam {

std::string ToString(FrontEndKind kind) {
  switch (kind) {
    case FrontEndKind::kClassicCamera:
      return "classic_camera";
  }
  return "unknown";
}

StatusOr<FrontEndKind> FrontEndKindFromString(const std::string& name) {
  if (name == "classic_camera") return FrontEndKind::kClassicCamera;
  return Status::Error("unknown front end '" + name + "' (valid: classic_camera)");
}

bool PipelineOptions::IsValid(std::string* error) const {
  std::string inner;
  if (!camera.IsValid(&inner)) {
    if (error) *error = "camera." + inner;
    return false;
  }
  return ratslam.IsValid(error);
}

namespace {
const PipelineOptions& Validated(const PipelineOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("PipelineOptions: " + error);
  return options;
}
}  // namespace

ReplayPipeline::ReplayPipeline(const PipelineOptions& options, const Dataset& dataset,
                               ImageLoader* images)
    : options_(Validated(options)),
      dataset_(dataset),
      images_(images),
      events_(MergeEvents(dataset)),
      slam_(std::make_unique<Ratslam>(options.ratslam)),
      camera_(options.camera) {
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
        ++state_.wifi_scans_seen;  // no Wi-Fi front end yet: counted, not used
        break;
      case EventType::kCompass:
        ++state_.compass_readings_seen;
        break;
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
  const double heading = state_.odometry_theta_rad + 0.5 * step.rotation_rad;
  state_.odometry_x_m += step.forward_m * std::cos(heading);
  state_.odometry_y_m += step.forward_m * std::sin(heading);
  state_.odometry_theta_rad = WrapAngle(state_.odometry_theta_rad + step.rotation_rad);

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
  const ImageRow& row = dataset_.images[event.index];
  const std::string where = "images.csv:" + std::to_string(row.line);
  StatusOr<GrayImage> image = images_->Load(dataset_.ImagePath(row));
  if (!image.ok()) return image.status().WithContext(where);
  const GrayImageView view{image->width, image->height, image->width, image->pixels.data()};
  StatusOr<ViewDecision> decision = camera_.Observe(view, row.time_s);
  if (!decision.ok()) return decision.status().WithContext(where + ": " + row.file);
  RATSLAM_RETURN_IF_ERROR(slam_->OnView(decision.value()));
  FrameRecord frame;
  frame.time_s = row.time_s;
  frame.template_id = decision->template_id;
  frame.is_new = decision->is_new;
  const auto current = slam_->experience_map().current();
  frame.experience_id = current ? static_cast<int64_t>(*current) : -1;
  state_.frames.push_back(frame);
  return Status::Ok();
}

ReplayPipeline::State ReplayPipeline::Snapshot() const {
  State snapshot = state_;
  snapshot.ratslam = slam_->GetState();
  snapshot.camera = camera_.state();
  return snapshot;
}

Status ReplayPipeline::Restore(const State& state) {
  if (state.events_total != events_.size()) {
    return Status::Error("saved map was made from a data set with " +
                         std::to_string(state.events_total) + " events; this one has " +
                         std::to_string(events_.size()));
  }
  if (state.next_event > events_.size()) return Status::Error("saved map is past the data set");
  auto slam = std::make_unique<Ratslam>(options_.ratslam);
  RATSLAM_RETURN_IF_ERROR(slam->SetState(state.ratslam));
  ClassicCameraMatcher camera(options_.camera);
  RATSLAM_RETURN_IF_ERROR(camera.SetState(state.camera));
  if (camera.size() != slam->local_view().size()) {
    return Status::Error("saved map: camera templates and local view cells differ in number");
  }
  slam_ = std::move(slam);
  camera_ = std::move(camera);
  state_ = state;
  state_.ratslam = {};
  state_.camera = {};
  return Status::Ok();
}

}  // namespace ratslam
