// Lock-step replay: one loop consumes a data set's time-stamped events in order (compass, Wi-Fi,
// images, odometry), routes views through the selected front end into the RatSLAM spine, and
// records what happened. Results depend only on the data and the options, never on wall-clock
// speed. The whole state can be taken out and put back, so that a replay can stop and resume.
#ifndef RATSLAM_FUSION_REPLAY_PIPELINE_H_
#define RATSLAM_FUSION_REPLAY_PIPELINE_H_

#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/status.h"
#include "dataset/dataset.h"
#include "dataset/image_loader.h"
#include "dataset/rosbag.h"
#include "dataset/video.h"
#include "fusion/fabmap/evaluation.h"
#include "fusion/front_end.h"
#include "fusion/wifi_sequence/wifi_sequence.h"
#include "ratslam/ratslam.h"
#include "ratslam/records.h"
#include "sensors/pedestrian_dead_reckoning.h"
#include "sensors/sequence_matcher.h"
#include "sensors/visual_odometry.h"

namespace ratslam::fusion {

// Everything a replay or an evaluation is configured by; one TOML section per member.
struct PipelineOptions {
  FrontEndSettings sensors;                        // front end choice and every sensor's options
  sensors::PdrOptions pdr;                         // odometry from phone logs
  sensors::VisualOdometryOptions visual_odometry;  // odometry from a camera alone
  RatslamOptions ratslam;
  wifi_sequence::WifiSequenceOptions
      wifi_sequence;                     // Wi-Fi sequence loop closure beside the front end
  fabmap::EvaluationOptions evaluation;  // `ratslam evaluate` only: how map and queries split
  dataset::BagTopics
      bag;  // which topics of a ROS bag make the data set (not part of a map's identity)
  dataset::VideoOptions video;  // how a video's frames get times and odometry (ditto)

  bool IsValid(std::string* error) const;
  // [sequence] recognise_views needs a front end that takes camera frames.
  bool SequenceRecognitionFits(std::string* error) const;

  // Visits (section name, options struct) pairs in file order.
  template <typename Visitor>
  void VisitSections(Visitor&& v) {
    v("front_end", sensors.front_end);
    v("camera", sensors.classic_camera);
    v("fused", sensors.fused);
    v("camera_12x9", sensors.camera_12x9);
    v("wifi", sensors.wifi);
    v("barometer", sensors.barometer);
    v("descriptors", sensors.descriptors);
    v("pdr", pdr);
    v("visual_odometry", visual_odometry);
    v("pose_cells", ratslam.pose_cells);
    v("local_view", ratslam.local_view);
    v("experience_map", ratslam.experience_map);
    v("action", ratslam.action);
    v("wifi_sequence", wifi_sequence);
    v("fabmap", sensors.fabmap.localiser.localiser);
    v("fabmap_front_end", sensors.fabmap.front_end);
    v("fabmap_model", sensors.fabmap.localiser.fabmap);
    v("visual_detector", sensors.fabmap.localiser.visual_detector);
    v("wifi_detector", sensors.fabmap.localiser.wifi_detector);
    v("visual_words", sensors.fabmap.features);
    v("vocabulary", sensors.fabmap.vocabulary);
    v("visual_model", sensors.fabmap.visual_model);
    v("wifi_words", sensors.fabmap.localiser.wifi_words);
    v("virtual_wifi", sensors.fabmap.localiser.virtual_wifi);
    v("evaluation", evaluation);
    v("sequence", sensors.sequence);
    v("bag", bag);
    v("video", video);
  }
};

struct ReplayProgress {
  uint64_t events_done = 0;
  uint64_t events_total = 0;
  double data_time_s = 0.0;
};

// The first pass of a calibrated replay ([fabmap_front_end] calibrate_earlier_session_log_odds):
// `options` with the Wi-Fi sequence loop closer on and the earlier sessions' threshold learnt,
// starting from match_log_odds so that no hand-set value enters. None when `options` ask for no
// calibration (another front end, or the key off).
std::optional<PipelineOptions> CalibrationPassOptions(const PipelineOptions& options);

struct ReplayControl {
  double until_time_s = std::numeric_limits<double>::infinity();  // stop after this data time
  const std::atomic<bool>* stop_requested = nullptr;              // checked between events
  std::function<void(const ReplayProgress&)> progress;  // called every progress_every events
  uint64_t progress_every = 500;
  // Called every checkpoint_every events with the pipeline (read only), e.g. to draw animation
  // frames; an error stops the replay.
  std::function<Status(const class ReplayPipeline&)> checkpoint;
  uint64_t checkpoint_every = 0;  // 0: never
};

class ReplayPipeline {
 public:
  struct State {
    Ratslam::State ratslam;
    std::string front_end;  // the front end's own encoding of its state
    uint64_t next_event = 0;
    uint64_t events_total = 0;  // of the data set it was made from
    double last_odometry_time_s = 0.0;
    bool have_odometry = false;
    double odometry_x_m = 0.0, odometry_y_m = 0.0, odometry_theta_rad = 0.0;
    std::vector<TrajectoryRecord> trajectory;
    std::vector<FrameRecord> frames;
    uint64_t wifi_scans_seen = 0;
    uint64_t compass_readings_seen = 0;
    uint64_t images_skipped = 0;  // images the front end does not use
    // Wi-Fi sequence loop closure: its poses and loops, the odometric travel so far, and
    // whether the sequence open at the end of the data was matched.
    wifi_sequence::WifiSequenceLoopCloser::State wifi_sequence;
    double travel_m = 0.0;
    bool wifi_sequence_flushed = false;
  };

  // `options` must be valid; throws std::invalid_argument otherwise. `dataset` and `images`
  // must outlive the pipeline.
  // The FABMAP, descriptor and custom front ends also need their `resources` (CreateFrontEnd).
  ReplayPipeline(const PipelineOptions& options, const dataset::Dataset& dataset,
                 ImageLoader* images, FrontEndResources resources = {});

  // Replays events from the current position until the data set ends, `until_time_s` passes, or
  // a stop is requested. On an error the state stays valid up to the last complete event.
  Status Run(const ReplayControl& control);

  // One input fed directly, outside the data set's events (a live source, or Python's
  // frame-by-frame session), through the same code the replay uses. Inputs must come in time
  // order; the data set's own events are not consumed.
  Status FeedOdometry(const OdometryRow& row);
  Status FeedImage(double time_s, const GrayImage& image);
  Status FeedWifi(const WifiScan& scan);
  // A place descriptor for the frame at `time_s` (the descriptor front end only).
  Status FeedDescriptor(double time_s, const std::vector<float>& values);
  void FeedCompass(const CompassRow& row);
  // A barometer reading (floors; [barometer] use_barometer). Fails on a reading the floor tracker
  // refuses (time going backwards, pressure outside 100-1,100 hPa).
  Status FeedPressure(const PressureSample& sample);

  // From now on, add the time of the front end and of the spine's stages to `times` (null: stop
  // timing); `times` must outlive the timing.
  void AttachStageTimes(StageTimes* times) {
    stage_times_ = times;
    slam_->AttachStageTimes(times);
  }

  bool finished() const { return state_.next_event >= events_.size(); }
  const Ratslam& slam() const { return *slam_; }
  const State& state() const { return state_; }
  // The run so far as plain records (what outputs and figures read).
  RunView View() const {
    return {slam_->experience_map(), slam_->pose_cells(), state_.frames, state_.trajectory,
            localising() ? &localisation_ : nullptr};
  }
  // A snapshot of the complete state (spine included).
  State Snapshot() const;
  // Restores a snapshot; fails if it does not belong to this data set and these options.
  Status Restore(const State& state);
  // Localisation only: takes the map of `map` (a snapshot of a run under these options, on any
  // data set) and replays this data set from its start on it, frozen (Ratslam::FreezeMap): no
  // templates, experiences or links join the map, Wi-Fi sequence loop closure is off, and every
  // view frame adds a LocalisationRecord, lost when no place has been recognised yet or when dead
  // reckoning has gone further than `lost_after_m` (straight line) from the last one. The pose
  // cells keep the map's final activity; views of known places pull them to the right place,
  // and a view of a known place while lost puts the robot there at once (relocalisation).
  Status AdoptMap(const State& map, double lost_after_m);
  // Replay's calibration ([fabmap_front_end] calibrate_earlier_session_log_odds): what the
  // front end learnt so far (FrontEnd::Learnt), and the same handed to this pipeline's front end
  // before its first event (fails after it, or when the front end takes no calibration).
  std::optional<FrontEndCalibration> Learnt() const { return front_end_->Learnt(); }
  Status Calibrate(const FrontEndCalibration& calibration);
  bool localising() const { return slam_->frozen(); }
  const std::vector<LocalisationRecord>& localisation() const { return localisation_; }
  const std::vector<dataset::Event>& events() const { return events_; }
  // Wi-Fi sequence loop closure (its poses, loops and similarity), whether enabled or not.
  const wifi_sequence::WifiSequenceLoopCloser& wifi_sequence() const { return *wifi_sequence_; }
  // The map's current estimate of a loop-closer pose: its anchor experience composed with the
  // pose's offset (the dead-reckoned position before the first experience).
  Pose2 MapPose(const wifi_sequence::SequencePose& pose) const;
  // How a FABMAP front end learnt its Wi-Fi model; nothing for the other front ends.
  std::optional<FabmapLearningReport> fabmap_learning() const {
    return front_end_->Report().fabmap_learning;
  }
  // The RSSI offsets removed per session ([fused] online_rssi_offset); empty otherwise.
  std::vector<double> rssi_offsets_db() const { return front_end_->Report().rssi_offsets_db; }
  // APs added to and dropped from templates by revisits ([fused] revisit_update_weight).
  std::optional<std::pair<uint64_t, uint64_t>> revisit_ap_updates() const {
    return front_end_->Report().revisit_ap_updates;
  }
  // What the barometer said ([barometer] use_barometer with a pressure stream); nothing otherwise.
  std::optional<FloorReport> floor_report() const { return front_end_->Report().floors; }
  // A template's floor relative to the first session's first level, when the front end knows.
  std::optional<int> template_floor(uint32_t id) const { return front_end_->TemplateFloor(id); }

 private:
  Status HandleOdometry(const dataset::Event& event);
  Status HandleImage(const dataset::Event& event);
  Status HandleWifi(const dataset::Event& event);
  Status HandlePressure(const dataset::Event& event);
  void AnnounceSession(double time_s);
  Status Apply(const FrameDecision& decision);
  Status AddSequencePose(const WifiScan& scan);
  // Whether the odometry moved just before `time_s` (FrontEnd::OnWalking).
  bool WalkingAt(double time_s) const;
  Status LinkLoop(const std::optional<wifi_sequence::SequenceLoop>& loop, double time_s);

  PipelineOptions options_;
  const dataset::Dataset& dataset_;
  ImageLoader* images_;
  std::vector<dataset::Event> events_;
  std::unique_ptr<Ratslam> slam_;
  FrontEndResources resources_;
  std::unique_ptr<FrontEnd> front_end_;
  std::unique_ptr<wifi_sequence::WifiSequenceLoopCloser> wifi_sequence_;
  State state_;                                   // the parts not held by slam_ and camera_
  std::vector<LocalisationRecord> localisation_;  // localisation runs only (not saved)
  double lost_after_m_ = 0.0;
  StageTimes* stage_times_ = nullptr;
};

}  // namespace ratslam::fusion

#endif  // RATSLAM_FUSION_REPLAY_PIPELINE_H_
