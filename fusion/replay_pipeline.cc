#include "fusion/replay_pipeline.h"

#include <cmath>
#include <stdexcept>

#include "common/circular.h"
#include "common/geometry.h"

namespace ratslam::fusion {

bool PipelineOptions::IsValid(std::string* error) const {
  std::string inner;
  auto check = [&](bool ok, const char* section) {
    if (!ok && error) *error = std::string(section) + "." + inner;
    return ok;
  };
  return check(sensors.classic_camera.IsValid(&inner), "camera") &&
         check(sensors.fused.IsValid(&inner), "fused") &&
         check(sensors.camera_12x9.IsValid(&inner), "camera_12x9") &&
         check(sensors.wifi.IsValid(&inner), "wifi") &&
         check(sensors.barometer.IsValid(&inner), "barometer") &&
         check(sensors.descriptors.IsValid(&inner), "descriptors") &&
         check(pdr.IsValid(&inner), "pdr") &&
         check(visual_odometry.IsValid(&inner), "visual_odometry") && ratslam.IsValid(error) &&
         check(wifi_sequence.IsValid(&inner), "wifi_sequence") && sensors.fabmap.IsValid(error) &&
         check(evaluation.IsValid(&inner), "evaluation") &&
         check(sensors.sequence.IsValid(&inner), "sequence") && check(bag.IsValid(&inner), "bag") &&
         check(video.IsValid(&inner), "video") && SequenceRecognitionFits(error);
}

bool PipelineOptions::SequenceRecognitionFits(std::string* error) const {
  if (!sensors.sequence.recognise_views || sensors.front_end.kind == FrontEndKind::kClassicCamera ||
      (sensors.front_end.kind == FrontEndKind::kFused && sensors.fused.use_camera)) {
    return true;
  }
  if (error) {
    *error =
        "sequence.recognise_views recognises camera frames: it needs [front_end] kind = "
        "\"classic_camera\", or \"fused\" with [fused] use_camera = true";
  }
  return false;
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

ReplayPipeline::ReplayPipeline(const PipelineOptions& options, const dataset::Dataset& dataset,
                               ImageLoader* images, FrontEndResources resources)
    : options_(Validated(options)),
      dataset_(dataset),
      images_(images),
      events_(dataset::MergeEvents(dataset)),
      slam_(std::make_unique<Ratslam>(options.ratslam)),
      resources_(std::move(resources)),
      front_end_(CreateFrontEnd(options.sensors, resources_)),
      wifi_sequence_(
          std::make_unique<wifi_sequence::WifiSequenceLoopCloser>(options.wifi_sequence)) {
  state_.events_total = events_.size();
}

Status ReplayPipeline::Run(const ReplayControl& control) {
  ReplayProgress progress;
  progress.events_total = events_.size();
  while (state_.next_event < events_.size()) {
    if (control.stop_requested && control.stop_requested->load()) break;
    const dataset::Event& event = events_[state_.next_event];
    if (event.time_s > control.until_time_s) break;
    Status status;
    switch (event.type) {
      case dataset::EventType::kOdometry:
        status = HandleOdometry(event);
        break;
      case dataset::EventType::kImage:
        status = HandleImage(event);
        break;
      case dataset::EventType::kWifi:
        status = HandleWifi(event);
        break;
      case dataset::EventType::kCompass:
        FeedCompass(dataset_.compass[event.index]);
        break;
      case dataset::EventType::kPressure:
        status = HandlePressure(event);
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
  if (finished() && options_.wifi_sequence.enabled && !localising() &&
      !state_.wifi_sequence_flushed) {
    // The sequence still open when the data ends (a walk that ends where it began) is matched
    // too, and the map relaxed until the new links settle, as no odometry step follows.
    state_.wifi_sequence_flushed = true;
    const double end_s = events_.empty() ? 0.0 : events_.back().time_s;
    RATSLAM_RETURN_IF_ERROR(LinkLoop(wifi_sequence_->Flush(end_s), end_s));
  }
  return Status::Ok();
}

Status ReplayPipeline::HandleOdometry(const dataset::Event& event) {
  return FeedOdometry(dataset_.odometry[event.index]);
}

Status ReplayPipeline::FeedOdometry(const OdometryRow& row) {
  const double dt = state_.have_odometry ? row.time_s - state_.last_odometry_time_s : 0.0;
  state_.have_odometry = true;
  state_.last_odometry_time_s = row.time_s;
  OdometryStep step;
  step.time_s = row.time_s;
  step.forward_m = row.forward_speed_m_per_s * dt;
  step.rotation_rad = row.turn_rate_rad_per_s * dt;
  state_.travel_m += std::abs(step.forward_m);
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

Status ReplayPipeline::HandleImage(const dataset::Event& event) {
  if (!front_end_->WantsImages()) {
    ++state_.images_skipped;
    return Status::Ok();
  }
  const ImageRow& row = dataset_.images[event.index];
  const std::string where = "images.csv:" + std::to_string(row.line);
  if (!front_end_->NeedsPixels()) return FeedImage(row.time_s, GrayImage()).WithContext(where);
  StatusOr<GrayImage> image = images_->Load(dataset_.ImagePath(row));
  if (!image.ok()) return image.status().WithContext(where);
  return FeedImage(row.time_s, image.value()).WithContext(where + ": " + row.file);
}

Status ReplayPipeline::FeedImage(double time_s, const GrayImage& image) {
  if (!front_end_->WantsImages()) {
    ++state_.images_skipped;
    return Status::Ok();
  }
  StatusOr<std::optional<FrameDecision>> decision = [&] {
    StageTimer timer(stage_times_ ? &stage_times_->front_end_s : nullptr);
    return front_end_->OnImage(time_s, image);
  }();
  if (!decision.ok()) return decision.status();
  return decision.value() ? Apply(*decision.value()) : Status::Ok();
}

Status ReplayPipeline::FeedDescriptor(double time_s, const std::vector<float>& values) {
  StatusOr<std::optional<FrameDecision>> decision = [&] {
    StageTimer timer(stage_times_ ? &stage_times_->front_end_s : nullptr);
    return front_end_->OnDescriptor(time_s, values);
  }();
  if (!decision.ok()) return decision.status();
  return decision.value() ? Apply(*decision.value()) : Status::Ok();
}

void ReplayPipeline::FeedCompass(const CompassRow& row) {
  ++state_.compass_readings_seen;
  front_end_->OnCompass(row.time_s, row.heading_rad);
  slam_->SetCompassHeading(front_end_->CompassHeading());
}

void ReplayPipeline::AnnounceSession(double time_s) {
  if (!dataset_.session_start_times_s.empty()) {
    front_end_->OnSessionStart(dataset_.session_start_times_s[dataset_.SessionAt(time_s)]);
  }
}

Status ReplayPipeline::HandleWifi(const dataset::Event& event) {
  const WifiScan& scan = dataset_.wifi[event.index];
  AnnounceSession(scan.time_s);
  return FeedWifi(scan);
}

Status ReplayPipeline::HandlePressure(const dataset::Event& event) {
  const PressureSample& sample = dataset_.pressure[event.index];
  AnnounceSession(sample.time_s);
  return FeedPressure(sample).WithContext("pressure.csv row " + std::to_string(event.index + 1));
}

Status ReplayPipeline::FeedPressure(const PressureSample& sample) {
  return front_end_->OnPressure(sample.time_s, sample.pressure_hpa);
}

Status ReplayPipeline::FeedWifi(const WifiScan& scan) {
  ++state_.wifi_scans_seen;
  front_end_->OnWalking(WalkingAt(scan.time_s));
  StatusOr<std::optional<FrameDecision>> decision = [&] {
    StageTimer timer(stage_times_ ? &stage_times_->front_end_s : nullptr);
    return front_end_->OnWifi(scan);
  }();
  if (!decision.ok()) return decision.status();
  if (decision.value()) RATSLAM_RETURN_IF_ERROR(Apply(*decision.value()));
  return options_.wifi_sequence.enabled && !localising() ? AddSequencePose(scan) : Status::Ok();
}

bool ReplayPipeline::WalkingAt(double time_s) const {
  // The newest odometry step moved, and came within a step interval of the scan (a walker's
  // odometry has a row per step; a standing one has none, or rows that do not move).
  const std::vector<TrajectoryRecord>& t = state_.trajectory;
  if (t.size() < 2) return false;
  const TrajectoryRecord& last = t.back();
  const TrajectoryRecord& before = t[t.size() - 2];
  const bool moved =
      last.odometry_x_m != before.odometry_x_m || last.odometry_y_m != before.odometry_y_m;
  return moved && time_s - last.time_s <= options_.pdr.max_step_interval_s;
}

Pose2 ReplayPipeline::MapPose(const wifi_sequence::SequencePose& pose) const {
  const ExperienceMap& map = slam_->experience_map();
  if (pose.anchor < 0 || static_cast<size_t>(pose.anchor) >= map.num_experiences()) {
    return pose.odometry;
  }
  const Experience& e = map.experience(static_cast<uint32_t>(pose.anchor));
  return Compose({e.x_m, e.y_m, e.theta_rad}, pose.anchor_offset.x_m, pose.anchor_offset.y_m,
                 pose.anchor_offset.theta_rad);
}

namespace {

// Travel added at each session start of a multi-session run: smoothing never mixes sessions, and
// every pose of an earlier session is far enough behind to be a loop candidate.
constexpr double kSessionGapM = 1000.0;

Pose2 Inverse(const Pose2& p) {
  const double c = std::cos(p.theta_rad), s = std::sin(p.theta_rad);
  return {-(c * p.x_m + s * p.y_m), s * p.x_m - c * p.y_m, WrapAngle(-p.theta_rad)};
}

Pose2 Then(const Pose2& a, const Pose2& b) { return Compose(a, b.x_m, b.y_m, b.theta_rad); }

}  // namespace

Status ReplayPipeline::AddSequencePose(const WifiScan& scan) {
  const ExperienceMap& map = slam_->experience_map();
  wifi_sequence::SequencePose pose;
  pose.time_s = scan.time_s;
  pose.travel_m =
      state_.travel_m + kSessionGapM * static_cast<double>(dataset_.SessionAt(scan.time_s));
  pose.odometry = {state_.odometry_x_m, state_.odometry_y_m, state_.odometry_theta_rad};
  pose.compass_heading_rad = front_end_->CompassHeading();
  if (map.current()) {
    pose.anchor = *map.current();
    pose.anchor_offset = {map.offset().forward_m, map.offset().left_m, map.offset().facing_rad};
  }
  std::vector<Point2> positions;
  positions.reserve(wifi_sequence_->size() + 1);
  for (size_t i = 0; i < wifi_sequence_->size(); ++i) {
    const Pose2 p = MapPose(wifi_sequence_->pose(i));
    positions.push_back({p.x_m, p.y_m});
  }
  const Pose2 here = MapPose(pose);
  positions.push_back({here.x_m, here.y_m});
  StatusOr<std::optional<wifi_sequence::SequenceLoop>> loop =
      wifi_sequence_->AddPose(pose, scan, positions);
  if (!loop.ok()) return loop.status();
  return LinkLoop(loop.value(), scan.time_s);
}

Status ReplayPipeline::LinkLoop(const std::optional<wifi_sequence::SequenceLoop>& loop,
                                double time_s) {
  if (!loop || !loop->accepted) return Status::Ok();
  bool added = false;
  size_t joined = 0, inliers = 0;  // inliers with both anchors; of them, places already joined
  for (const wifi_sequence::SequenceCorrespondence& c : loop->correspondences) {
    if (!c.inlier) continue;
    const wifi_sequence::SequencePose& now = wifi_sequence_->pose(c.current_pose);
    const wifi_sequence::SequencePose& then = wifi_sequence_->pose(c.past_pose);
    front_end_->OnVerifiedRevisit(now.time_s, then.time_s);
    if (now.anchor < 0 || then.anchor < 0) continue;
    // Where the front end has already joined the two places, a second, differently measured
    // link only pulls against its own (on the IPIN routes such links made b_out's maps worse).
    // Poses this close are never loop candidates, so without a front end's closures nothing is
    // skipped.
    ++inliers;
    if (slam_->experience_map().JoinedWithin(static_cast<uint32_t>(then.anchor),
                                             static_cast<uint32_t>(now.anchor),
                                             options_.wifi_sequence.min_loop_travel_m)) {
      ++joined;
      continue;
    }
    // The current pose seen from the past one (the verified fit), carried to their anchors:
    // anchor_now in anchor_then's frame = offset_then * relative * offset_now^-1.
    const Pose2 relative = wifi_sequence_->RelativePose(*loop, c.current_pose, c.past_pose);
    const Pose2 link = Then(Then(then.anchor_offset, relative), Inverse(now.anchor_offset));
    StatusOr<bool> linked = slam_->AddConstraint(static_cast<uint32_t>(then.anchor),
                                                 static_cast<uint32_t>(now.anchor), link, time_s);
    if (!linked.ok()) return linked.status();
    added |= linked.value();
  }
  if (!added) {
    // Nothing reached the map: say so, so that summaries count only loops that linked places.
    std::string why = "no inlier has an experience yet";
    if (inliers > 0 && joined == inliers) {
      why = "the map already joins those places";
    } else if (inliers > 0) {
      why = std::to_string(joined) + " of " + std::to_string(inliers) +
            " left out where the map already joins the places, the rest join experiences "
            "linked already";
    }
    wifi_sequence_->SetOutcome(loop->id, std::string(wifi_sequence::kNoLinkOutcome) + ": " + why);
  } else if (joined > 0) {
    wifi_sequence_->SetOutcome(loop->id, "accepted; " + std::to_string(joined) + " of " +
                                             std::to_string(inliers) +
                                             " links left out: the map already joins those places");
  }
  if (added && finished()) {
    for (int i = 0; i < 100; ++i) slam_->RelaxExperienceMap();
  }
  return Status::Ok();
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
  if (localising()) {
    const ExperienceMap& map = slam_->experience_map();
    LocalisationRecord r;
    r.time_s = frame.time_s;
    r.experience_id = frame.experience_id;
    map.CurrentPose(&r.x_m, &r.y_m, &r.theta_rad);
    r.lost = slam_->Lost(lost_after_m_);
    localisation_.push_back(r);
  }
  return Status::Ok();
}

ReplayPipeline::State ReplayPipeline::Snapshot() const {
  State snapshot = state_;
  snapshot.ratslam = slam_->GetState();
  snapshot.front_end = front_end_->EncodeState();
  snapshot.wifi_sequence = wifi_sequence_->state();
  return snapshot;
}

std::optional<PipelineOptions> CalibrationPassOptions(const PipelineOptions& options) {
  const FabmapFrontEndOptions& f = options.sensors.fabmap.front_end;
  if (options.sensors.front_end.kind != FrontEndKind::kFabmap ||
      !f.calibrate_earlier_session_log_odds) {
    return std::nullopt;
  }
  PipelineOptions first = options;
  FabmapFrontEndOptions& g = first.sensors.fabmap.front_end;
  g.calibrate_earlier_session_log_odds = false;
  g.learn_earlier_session_log_odds = true;
  g.earlier_session_log_odds = f.match_log_odds;
  first.wifi_sequence.enabled = true;
  return first;
}

Status ReplayPipeline::Calibrate(const FrontEndCalibration& calibration) {
  if (state_.next_event != 0) {
    return Status::Error("calibration: the replay has already started");
  }
  return front_end_->Calibrate(calibration);
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
  slam->AttachStageTimes(stage_times_);
  std::unique_ptr<FrontEnd> front_end = CreateFrontEnd(options_.sensors, resources_);
  RATSLAM_RETURN_IF_ERROR(front_end->DecodeState(state.front_end));
  auto wifi_sequence =
      std::make_unique<wifi_sequence::WifiSequenceLoopCloser>(options_.wifi_sequence);
  RATSLAM_RETURN_IF_ERROR(wifi_sequence->SetState(state.wifi_sequence));
  for (const wifi_sequence::SequencePose& p : state.wifi_sequence.poses) {
    if (p.anchor >= static_cast<int64_t>(state.ratslam.experience_map.experiences.size())) {
      return Status::Error(
          "saved map: a Wi-Fi sequence pose refers to an experience that does "
          "not exist");
    }
  }
  if (front_end->size() != slam->local_view().size()) {
    return Status::Error("saved map: front-end templates and local view cells differ in number");
  }
  slam_ = std::move(slam);
  front_end_ = std::move(front_end);
  wifi_sequence_ = std::move(wifi_sequence);
  state_ = state;
  state_.ratslam = {};
  state_.front_end.clear();
  state_.wifi_sequence = {};
  return Status::Ok();
}

Status ReplayPipeline::AdoptMap(const State& map, double lost_after_m) {
  if (!(lost_after_m > 0.0) || !std::isfinite(lost_after_m)) {
    return Status::Error("localisation: lost_after_m must be positive and finite");
  }
  // The map, with everything that belongs to the run that made it set back to a start.
  State start;
  start.ratslam = map.ratslam;
  start.ratslam.counters = {};
  start.front_end = map.front_end;
  start.events_total = events_.size();
  RATSLAM_RETURN_IF_ERROR(Restore(start));
  slam_->FreezeMap(events_.empty() ? 0.0 : events_.front().time_s, lost_after_m);
  front_end_->SettleForLocalisation();
  localisation_.clear();
  lost_after_m_ = lost_after_m;
  return Status::Ok();
}

}  // namespace ratslam::fusion
