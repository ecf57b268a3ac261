#include "session/replay_session.h"

#include <cmath>
#include <stdexcept>
#include <utility>

#include "dataset/dataset_loader.h"
#include "dataset/visual_odometry_source.h"
#include "io/config.h"
#include "io/front_end_resources.h"
#include "io/map_file.h"

namespace ratslam::session {
Status CheckSameConfiguration(const io::MapFile& map, const fusion::PipelineOptions& now) {
  if (!map.config.empty()) {
    StatusOr<fusion::PipelineOptions> before = io::ParseMapConfig(map.config, map.format_version);
    if (!before.ok()) return before.status();
    std::vector<std::string> differences = io::ConfigDifferences(*before, now);
    // How a bag or a video was read, and where a data set's descriptors are, say nothing
    // about the map.
    std::erase_if(differences, [](const std::string& d) {
      return d.rfind("bag.", 0) == 0 || d.rfind("video.", 0) == 0 ||
             d.rfind("descriptors.file:", 0) == 0;
    });
    if (differences.empty()) return Status::Ok();
    std::string keys;
    for (const std::string& d : differences) keys += "\n  " + d;
    return Status::Error("the map was made with a different configuration (map -> now):" + keys);
  }
  StatusOr<uint64_t> then = io::FingerprintAsOfMapVersion(now, map.format_version);
  if (!then.ok()) {
    return then.status().WithContext("the map was made with a different configuration");
  }
  if (*then != map.config_fingerprint) {
    return Status::Error("the map was made with a different configuration (a format " +
                         std::to_string(map.format_version) +
                         " map names no keys; print the one you used with ratslam print-config)");
  }
  return Status::Ok();
}

ReplaySession::ReplaySession(ReplaySessionOptions options, SessionEnvironment environment)
    : options_(std::move(options)), env_(environment) {
  if (env_.out == nullptr) throw std::invalid_argument("ReplaySession needs an output folder");
  if (env_.clock == nullptr) env_.clock = &system_clock_;
  if (env_.progress == nullptr) env_.progress = &no_progress_;
  if (env_.images == nullptr) {
    own_images_ = std::make_unique<dataset::FileImageLoader>();
    env_.images = own_images_.get();
  }
  fingerprint_ = io::ConfigFingerprint(options_.pipeline);
}

ReplaySession::~ReplaySession() = default;

Status ReplaySession::Load() {
  std::string error;
  if (!options_.pipeline.IsValid(&error)) return Status::Error("configuration: " + error);
  if (options_.localise) {
    if (options_.load_map.empty()) return Status::Error("localisation needs a map (--load-map)");
    if (!options_.save_map.empty()) {
      return Status::Error("localisation does not change the map: there is nothing to save");
    }
    if (!(options_.lost_after_m > 0.0) || !std::isfinite(options_.lost_after_m)) {
      return Status::Error("localisation: the lost distance must be positive and finite");
    }
  }
  dataset::PhoneLogOptions phone;
  phone.lenient = options_.lenient;
  phone.pdr = options_.pipeline.pdr;
  StatusOr<dataset::Dataset> dataset = dataset::LoadSessions(
      options_.data, phone, 1.0, options_.pipeline.bag, options_.pipeline.video);
  if (!dataset.ok()) return dataset.status();
  if (options_.pipeline.visual_odometry.enabled) {
    RATSLAM_RETURN_IF_ERROR(dataset::ReplaceOdometryWithVisual(&dataset.value(), env_.images,
                                                               options_.pipeline.visual_odometry)
                                .WithContext("visual odometry"));
  }
  if (dataset->odometry.empty()) {
    return Status::Error("data set '" + dataset->name +
                         "' has no odometry stream: set [visual_odometry] enabled = true to "
                         "take odometry from its images");
  }
  RATSLAM_RETURN_IF_ERROR(fusion::CheckFrontEndInputs(options_.pipeline.sensors, *dataset));
  dataset_ = std::move(dataset).value();
  return env_.out->Write("config.toml",
                         "# Resolved configuration of this run (ratslam print-config format).\n" +
                             io::PrintConfig(options_.pipeline));
}

Status ReplaySession::Prepare() {
  if (!dataset_) return Status::Error("replay session: Prepare before Load");
  StatusOr<fusion::FrontEndResources> resources =
      io::LoadFrontEndResources(options_.pipeline.sensors, options_.data, *dataset_, *env_.images);
  if (!resources.ok()) return resources.status();
  if (options_.pipeline.sensors.front_end.kind == fusion::FrontEndKind::kCustom) {
    if (!env_.custom_front_end) {
      return Status::Error(
          "front_end.kind is custom, but no front end was given (a C++ program passes its "
          "factory as SessionEnvironment::custom_front_end)");
    }
    resources->custom = env_.custom_front_end;
  }
  resources_ = *resources;
  auto pipeline = std::make_unique<fusion::ReplayPipeline>(
      options_.pipeline, *dataset_, env_.images, std::move(resources).value());
  if (!options_.load_map.empty()) {
    const std::string& path = options_.load_map;
    StatusOr<io::MapFile> map = io::LoadMapFile(path);
    if (!map.ok()) return map.status();
    RATSLAM_RETURN_IF_ERROR(CheckSameConfiguration(*map, options_.pipeline).WithContext(path));
    if (options_.localise) {
      RATSLAM_RETURN_IF_ERROR(
          pipeline->AdoptMap(map->state, options_.lost_after_m).WithContext(path));
      pipeline_ = std::move(pipeline);
      return Status::Ok();
    }
    if (map->dataset_name != dataset_->name) {
      return Status::Error(path + ": the map was made from data set '" + map->dataset_name +
                           "', not '" + dataset_->name + "'");
    }
    RATSLAM_RETURN_IF_ERROR(pipeline->Restore(map->state).WithContext(path));
  }
  pipeline_ = std::move(pipeline);
  return Status::Ok();
}

Status ReplaySession::Replay(const ReplayCheckpoint& checkpoint) {
  if (!pipeline_) return Status::Error("replay session: Replay before Prepare");
  fusion::ReplayControl control;
  control.until_time_s = options_.until_s;
  control.stop_requested = env_.stop_requested;
  control.progress = [this](const fusion::ReplayProgress& p) {
    env_.progress->Update({"replay", p.events_done, p.events_total, p.data_time_s});
  };
  // A failed calibration pass leaves the configured threshold; the main pass still runs, so
  // that whatever it makes before meeting the same data error is written and saved.
  const Status calibrated = CalibrationPass(control);
  control.checkpoint = checkpoint.callback;
  control.checkpoint_every = checkpoint.callback ? checkpoint.every : 0;
  const uint64_t frames_before = pipeline_->state().frames.size();
  const double start = env_.clock->Seconds();
  result_.replay = pipeline_->Run(control);
  if (result_.replay.ok()) result_.replay = calibrated;
  result_.wall_seconds = env_.clock->Seconds() - start;
  env_.progress->Finish();
  result_.frames_this_run = pipeline_->state().frames.size() - frames_before;
  result_.interrupted = env_.stop_requested != nullptr && env_.stop_requested->load();
  result_.finished = pipeline_->finished();
  return result_.replay;
}

Status ReplaySession::CalibrationPass(const fusion::ReplayControl& main) {
  std::optional<fusion::PipelineOptions> first = fusion::CalibrationPassOptions(options_.pipeline);
  // A map localised on, or resumed after its first event, carries the threshold its run was
  // calibrated with.
  if (!first || options_.localise || pipeline_->state().next_event != 0) return Status::Ok();
  fusion::ReplayControl control;
  control.until_time_s = main.until_time_s;
  control.stop_requested = main.stop_requested;
  control.progress = [this](const fusion::ReplayProgress& p) {
    env_.progress->Update({"calibrate", p.events_done, p.events_total, p.data_time_s});
  };
  const double start = env_.clock->Seconds();
  fusion::ReplayPipeline pass(*first, *dataset_, env_.images, resources_);
  Status ran = pass.Run(control);
  result_.calibration_wall_seconds = env_.clock->Seconds() - start;
  env_.progress->Finish();
  RATSLAM_RETURN_IF_ERROR(ran.WithContext("calibration pass"));
  // Stopped: the main pass stops at once too, and a resume of its map calibrates afresh.
  if (env_.stop_requested != nullptr && env_.stop_requested->load()) return Status::Ok();
  std::optional<fusion::FrontEndCalibration> learnt = pass.Learnt();
  if (!learnt) return Status::Error("calibration pass: the front end learnt nothing");
  result_.calibration = learnt;
  return pipeline_->Calibrate(*learnt).WithContext("calibration");
}

Status ReplaySession::WriteOutputs() {
  if (!pipeline_) return Status::Error("replay session: WriteOutputs before Prepare");
  io::RunInfo info;
  info.wall_seconds = result_.wall_seconds;
  if (result_.calibration) info.calibration_wall_seconds = result_.calibration_wall_seconds;
  info.frames_this_run = result_.frames_this_run;
  info.interrupted = result_.interrupted;
  info.config_path = options_.config_path;
  info.config_fingerprint = fingerprint_;
  (options_.localise ? info.localised_on : info.resumed_from) = options_.load_map;
  info.lost_after_m = options_.lost_after_m;
  info.provenance = options_.provenance;
  info.inputs = options_.data;
  StatusOr<io::RunSummary> summary = io::WriteRunOutputs(*env_.out, *pipeline_, *dataset_, info);
  if (summary.ok()) {
    result_.summary = std::move(summary).value();
    result_.outputs = Status::Ok();
  } else {
    result_.outputs = summary.status();
  }
  return result_.outputs;
}

Status ReplaySession::SaveMap() {
  if (!pipeline_) return Status::Error("replay session: SaveMap before Prepare");
  if (options_.localise) return Status::Ok();  // the map is as it was loaded
  std::string path = options_.save_map;
  if (path.empty() && (result_.interrupted || !result_.replay.ok() || !result_.outputs.ok())) {
    path = env_.out->Path("interrupted.map");
  }
  if (path.empty()) return Status::Ok();
  io::MapFile map;
  map.config_fingerprint = fingerprint_;
  map.dataset_name = dataset_->name;
  map.config = io::PrintConfig(options_.pipeline, false);
  map.state = pipeline_->Snapshot();
  result_.save = io::SaveMapFile(map, path);
  if (result_.save.ok()) result_.saved_map = path;
  return result_.save;
}

StatusOr<ReplayResult> ReplaySession::Run(const ReplayCheckpoint& checkpoint) {
  RATSLAM_RETURN_IF_ERROR(Load());
  RATSLAM_RETURN_IF_ERROR(Prepare());
  // From here on every stage runs: outputs and the map are written whatever the replay did, and
  // the map is saved even when the outputs could not be written (it may go to another disk).
  (void)Replay(checkpoint);
  (void)WriteOutputs();
  (void)SaveMap();
  return result_;
}

}  // namespace ratslam::session
