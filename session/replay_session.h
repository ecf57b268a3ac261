// A replay as a library session: what `ratslam replay` does, as named stages that return errors,
// driven by the command line, by sweeps, by tests and by bindings alike. Side effects go through
// the environment (output folder, clock, progress, image loader, stop flag), so tests use fakes.
//
// Stages, in order: Load (data sets, visual odometry, the resolved config written), Prepare (the
// FABMAP front end's models, the pipeline, resuming from a saved map), Replay (with
// [fabmap_front_end] calibrate_earlier_session_log_odds first a calibration pass over the same
// data, fusion::CalibrationPassOptions, whose learnt threshold the main pass starts with),
// WriteOutputs, SaveMap. Run() calls them all and returns a ReplayResult; once the replay has
// started, every later stage runs even when an earlier one failed, so that nothing computed is
// lost.
#ifndef RATSLAM_SESSION_REPLAY_SESSION_H_
#define RATSLAM_SESSION_REPLAY_SESSION_H_

#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/clock.h"
#include "common/output_folder.h"
#include "common/progress.h"
#include "common/provenance.h"
#include "common/status.h"
#include "dataset/dataset.h"
#include "dataset/image_loader.h"
#include "fusion/replay_pipeline.h"
#include "io/map_file.h"
#include "io/run_outputs.h"

namespace ratslam::session {

struct ReplaySessionOptions {
  fusion::PipelineOptions pipeline;
  std::string config_path;        // as given by the user, for the summary; empty: defaults
  std::vector<std::string> data;  // one data set, or several sessions of one run
  bool lenient = false;           // skip (and count) malformed lines of phone logs
  std::string load_map;           // resume from this map file (or localise on it)
  // Localisation only (ReplayPipeline::AdoptMap): replay `data` from its start on the frozen map
  // of load_map, which any data set may have made; nothing is saved.
  bool localise = false;
  double lost_after_m = 5.0;  // a localisation frame this far from its last place is lost
  std::string save_map;       // save the final state here
  double until_s = std::numeric_limits<double>::infinity();  // stop after this data time
  RunProvenance provenance;  // command line and start time, for summary.json's `run`
};

// What the session needs from outside. `out` is required; the others may be null (system clock,
// no progress, images from files, no stop request).
struct SessionEnvironment {
  OutputFolder* out = nullptr;
  const Clock* clock = nullptr;
  ProgressSink* progress = nullptr;
  ImageLoader* images = nullptr;
  const std::atomic<bool>* stop_requested = nullptr;  // checked between events
  // [front_end] kind = "custom": makes the run's front end (fusion/front_end.h, "Writing a
  // front end"); called again for each restore.
  fusion::FrontEndFactory custom_front_end;
};

// Called every `every` events with the pipeline (read only), e.g. to draw animation frames; an
// error stops the replay like a data error does.
struct ReplayCheckpoint {
  std::function<Status(const fusion::ReplayPipeline&)> callback;
  uint64_t every = 0;  // 0: never
};

struct ReplayResult {
  std::optional<io::RunSummary> summary;  // present when the outputs were written
  Status replay;                          // the replay itself (a data error stops it early)
  Status outputs;                         // writing the run's files
  Status save;                            // saving the map, when one was saved
  std::string saved_map;                  // where the state was saved; empty when not saved
  bool interrupted = false;               // a stop was requested
  bool finished = false;                  // the data set was replayed to its end
  uint64_t frames_this_run = 0;
  double wall_seconds = 0.0;  // of the replay stage (its calibration pass not included)
  // [fabmap_front_end] calibrate_earlier_session_log_odds: what the first pass learnt (none
  // when no calibration pass ran: another configuration, or a resumed or localised map) and
  // how long it took.
  std::optional<fusion::FrontEndCalibration> calibration;
  double calibration_wall_seconds = 0.0;
  bool ok() const { return replay.ok() && outputs.ok() && save.ok(); }
};

// A map resumes (or is localised on) only under the configuration that made it. Maps of
// format 3 and later carry it, so the error names every key that differs; format 2 maps hold a
// fingerprint, compared as it was then.
Status CheckSameConfiguration(const io::MapFile& map, const fusion::PipelineOptions& now);

class ReplaySession {
 public:
  ReplaySession(ReplaySessionOptions options, SessionEnvironment environment);
  ~ReplaySession();

  Status Load();
  Status Prepare();
  Status Replay(const ReplayCheckpoint& checkpoint = {});
  Status WriteOutputs();
  // Saves to save_map; when none is given, to the output folder's interrupted.map if the replay
  // failed, was interrupted, or its outputs could not be written.
  Status SaveMap();

  // All stages. An error of Load or Prepare (nothing replayed yet) is returned as such; after
  // that the result says what each stage did.
  StatusOr<ReplayResult> Run(const ReplayCheckpoint& checkpoint = {});

  const ReplaySessionOptions& options() const { return options_; }
  const dataset::Dataset& dataset() const { return *dataset_; }          // after Load
  const fusion::ReplayPipeline& pipeline() const { return *pipeline_; }  // after Prepare
  const ReplayResult& result() const { return result_; }

 private:
  // The calibration pass, before the main replay; Ok when there is none to make.
  Status CalibrationPass(const fusion::ReplayControl& control);

  ReplaySessionOptions options_;
  SessionEnvironment env_;
  SteadyClock system_clock_;
  SilentProgress no_progress_;
  std::unique_ptr<ImageLoader> own_images_;
  std::optional<dataset::Dataset> dataset_;
  fusion::FrontEndResources resources_;  // kept for the calibration pass's pipeline
  std::unique_ptr<fusion::ReplayPipeline> pipeline_;
  uint64_t fingerprint_ = 0;
  ReplayResult result_;
};

}  // namespace ratslam::session

#endif  // RATSLAM_SESSION_REPLAY_SESSION_H_
