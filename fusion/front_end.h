// Front ends decide which local view is active. The replay pipeline hands them every event; a
// front end answers with a frame decision when an event makes a frame (a camera image, or a
// Wi-Fi scan when no camera is used).
//
// kClassicCamera: the OpenRatSLAM camera matcher (sensors/classic_camera_matcher.h).
// kFused: the Wi-Fi RatSLAM paper's front end (section III): 12x9 camera templates (eq. 7),
// Wi-Fi fingerprints (eqs. 3-6) and a compass (eq. 2), combined by the b_out rule (eqs. 8-12):
// the best match per sensor counts only if it reaches the sensor's threshold and is not among
// the last k templates (k in templates and/or seconds); the camera is preferred when it matches,
// else Wi-Fi, else a new joint template (camera view + newest Wi-Fi scan + heading) is stored.
// Our reading of "novel": a best match above threshold that is merely recent is familiar, not
// novel. Taken literally, eqs. 10-12 would store a new template at every frame while the robot
// stands still (its best match is always the template just stored). So a recent best above
// threshold re-uses that template without pose-cell injection (as OpenRatSLAM treats its newest
// templates); only both sensors below threshold make a new template.
// Wi-Fi is evaluated at the camera rate with the newest scan; scans older than max_wifi_age_s
// count as absent. Any sensor can be switched off (Wi-Fi only, camera only, fused).
// kFabmap: FABMAP (fusion/fabmap) decides: a place it recognises with at least
// match_probability is the active view; otherwise (the new place wins) the observation becomes a
// new place and template. With decide_by_log_odds the best mapped place is the active view when
// its log odds against the new place reach match_log_odds (the log of the two posteriors' ratio,
// from the likelihoods, so finite where the posteriors saturate at 0 and 1): the rule whose
// threshold `ratslam evaluate` learns ([evaluation] calibrate_new_place). Any FABMAP mode works
// (vision, wifi, early, late, sequential). The Wi-Fi words, tree and virtual samples come from an
// exploration of the data set's own scans (the fusion paper's section 3: Wi-Fi vocabularies exist
// only after exploring), spaced by odometry travel and time; the visual model is loaded from
// [visual_model] file or trained.
// Floors ([barometer] use_barometer with a pressure stream; fused and FABMAP front ends): each
// session's barometer gives levels (sensors/barometer.h); a template stores its session and
// level, or "unknown" when made on the stairs (in transit). A session is on its first level
// until the first dwell (walks start standing). A match needs the barometer to agree: within a
// session the same level; across sessions the same floor in the map's frame, where a later
// session starts with offset 0 to the first (walks of one building usually start on one floor)
// and Wi-Fi revises it: each scan on a level votes with its best confident match among earlier
// sessions' templates on a level, whatever their floor, when that match beats the best on every
// other floor by 1.5 times (an ambiguous scan abstains); a vote says the template's floor minus
// ours, and a value other than 0 that leads every other (0 included) by floor_offset_min_votes
// moves the session's offset. A query or template of unknown floor matches nothing that has a
// floor, so a scan taken on the stairs becomes a new template. Sessions without barometer
// readings are unconstrained, as before. FABMAP: the best place the barometer allows must still
// pass the decision rule (match_probability, or match_log_odds with decide_by_log_odds); its
// votes use the posterior of places as the score and match_probability as the threshold.
// kDescriptors: per-image descriptors computed elsewhere (fusion/descriptor_table.h) matched by
// cosine similarity with min_similarity and the same recency rule; pixels are never loaded.
// kCustom: a front end of your own (see "Writing a front end" below FrontEnd).
#ifndef RATSLAM_FUSION_FRONT_END_H_
#define RATSLAM_FUSION_FRONT_END_H_

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "common/schema.h"
#include "common/status.h"
#include "fusion/descriptor_table.h"
#include "fusion/fabmap/localiser.h"
#include "fusion/fabmap/visual_model.h"
#include "fusion/fabmap/vocabulary.h"
#include "ratslam/local_view_cells.h"
#include "ratslam/records.h"
#include "sensors/barometer.h"
#include "sensors/classic_camera_matcher.h"
#include "sensors/dataset/dataset.h"
#include "sensors/dataset/image_loader.h"
#include "sensors/kernel_camera_matcher.h"
#include "sensors/sequence_matcher.h"
#include "sensors/wifi_fingerprint_matcher.h"

namespace ratslam {

// kDescriptors without a table takes its descriptors from FrontEnd::OnDescriptor only.
// kNone matches nothing: every Wi-Fi scan is a new template (Wi-Fi sequence loop closure alone).
enum class FrontEndKind { kClassicCamera, kFused, kFabmap, kNone, kDescriptors, kCustom };
std::string ToString(FrontEndKind kind);
// Fails with the list of valid names.
StatusOr<FrontEndKind> FrontEndKindFromString(const std::string& name);

struct FrontEndOptions {
  FrontEndKind kind = FrontEndKind::kClassicCamera;  // which front end decides the local view

  bool IsValid(std::string*) const { return true; }
  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("kind", kind,
      "front end that decides the active local view: classic_camera, fused, fabmap, none "
      "(every Wi-Fi scan a new template), descriptors (per-image vectors from a file) or custom "
      "(a C++ front end handed to the session)",
      schema::Any());
  }
};

struct FusedOptions {
  bool use_camera = false;      // 12x9 camera templates (eq. 7)
  bool use_wifi = true;         // Wi-Fi fingerprints (eqs. 3-6)
  bool use_compass = false;     // heading per template; relative orientation of eq. 2
  int recency_templates = 0;    // k: a match must be at least this many templates old
  double recency_s = 40.0;      // k: and at least this many seconds old (paper: 40 s)
  double max_wifi_age_s = 5.0;  // an older newest scan counts as absent
  // Per-device RSSI offset, estimated online: each scan of a later session is compared with the
  // earlier sessions' templates by the spread of its RSSI differences (a constant offset costs
  // nothing there); the median difference to the best one is an estimate, and once there are
  // rssi_offset_min_estimates of them their median is removed from the session's scans (in
  // matching and in the templates it stores). No ground truth, no per-phone constant.
  bool online_rssi_offset = false;
  int rssi_offset_min_common_aps = 5;  // an estimate needs this many APs in common
  int rssi_offset_min_estimates = 10;  // estimates before the offset is applied
  // Maps that keep up with access points changing after them (long-term data): a scan whose
  // Wi-Fi match to an old template (a revisit, past the recency of eqs. 10-11) reaches this
  // weight updates that template's fingerprint (WifiFingerprintMatcher::FollowRevisit: the APs
  // it heard that the template lacks are added, the template's strong APs it did not hear are
  // dropped), once per scan. 0: off.
  double revisit_update_weight = 0.0;

  bool IsValid(std::string* error) const;

  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("use_camera", use_camera, "use 12x9 camera templates (eq. 7); frames are camera images",
      schema::Any());
    v("use_wifi", use_wifi, "use Wi-Fi fingerprints (eqs. 3-6); without a camera, scans are frames",
      schema::Any());
    v("use_compass", use_compass,
      "store a heading with each template; matches give the relative orientation of eq. 2",
      schema::Any());
    v("recency_templates", recency_templates,
      "k of eqs. 10-11 in templates: newer matches do not count",
      schema::Unit("templates").NonNegative());
    v("recency_s", recency_s, "k of eqs. 10-11 in seconds: matches newer than this do not count",
      schema::Unit("s").NonNegative());
    v("max_wifi_age_s", max_wifi_age_s, "a Wi-Fi scan older than this counts as absent at a frame",
      schema::Unit("s").NonNegative());
    v("online_rssi_offset", online_rssi_offset,
      "estimate each later session's RSSI offset to the earlier sessions' templates online and "
      "remove it from its scans (phones that read several dB apart)",
      schema::Any());
    v("rssi_offset_min_common_aps", rssi_offset_min_common_aps,
      "APs a scan must share with an earlier session's template to estimate the offset",
      schema::Unit("APs").AtLeast(1));
    v("rssi_offset_min_estimates", rssi_offset_min_estimates,
      "offset estimates of a session before its median is applied",
      schema::Unit("scans").AtLeast(1));
    v("revisit_update_weight", revisit_update_weight,
      "a revisit whose Wi-Fi match reaches this weight (eq. 6) updates the template's "
      "fingerprint once per scan: the scan's APs it lacks are added, its APs above "
      "penalty_floor_dbm that the scan did not hear are dropped (APs changed since the map was "
      "made); 0: off",
      schema::Unit("").Within(0, 1));
  }
};

// Floors from the barometer for the front ends that match Wi-Fi (fused and FABMAP; see
// "Floors" above): the switch, the vote lead, and the floor tracker's own settings.
struct FloorOptions {
  bool use_barometer = false;      // floors from a pressure stream, when there is one
  int floor_offset_min_votes = 3;  // lead of a floor offset over any other value
  BarometerOptions tracker;

  bool IsValid(std::string* error) const;
  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("use_barometer", use_barometer,
      "with a pressure stream: give templates a floor (level) from the barometer and never match "
      "across floors or from the stairs (fused and FABMAP front ends); without one, no effect",
      schema::Any());
    v("floor_offset_min_votes", floor_offset_min_votes,
      "a later session's floors start level with the first session's; its Wi-Fi matches to "
      "earlier sessions vote, and a floor offset that leads every other by this many votes "
      "replaces the current one",
      schema::Unit("votes").AtLeast(1));
    tracker.VisitFields(v);
  }
};

// What the barometer said over a run (front ends with use_barometer and a pressure stream).
struct FloorReport {
  uint64_t pressure_readings = 0;
  uint64_t floor_changes = 0;         // over all sessions (sensors/barometer.h)
  uint64_t frames_floor_unknown = 0;  // frames on the stairs or before a session's first level
  uint64_t new_templates_by_floor_rule = 0;  // would have matched a template on another floor
  uint64_t templates_with_floor = 0;
  uint64_t floor_offset_changes = 0;  // times Wi-Fi votes moved a session's floor offset
  // By session: the offset of its floors to the first session's.
  std::vector<int> session_floor_offsets;
};

// Where the FABMAP front end's Wi-Fi words, tree and unknown world come from.
//   kWholeDataSet: every scan of the data set, future sessions included (an exploration done
//     before the run, as in the fusion paper's benchmark; not causal).
//   kOnline: only the scans seen so far: learnt after `online_first_scans` scans and again each
//     time the count doubles (mapped places are re-added to the relearnt model); before the first
//     model every frame is a new place. A decision at time t never depends on data after t.
enum class WifiLearning { kWholeDataSet, kOnline };
std::string ToString(WifiLearning learning);
StatusOr<WifiLearning> WifiLearningFromString(const std::string& name);

struct FabmapFrontEndOptions {
  double match_probability = 0.5;  // least posterior of the best place to re-use its template
  int recency_templates = 0;       // a match this many templates old or newer: no injection
  double recency_s = 10.0;         // nor one made less than this long ago
  double max_wifi_age_s = 5.0;     // an older newest scan counts as absent at an image frame
  WifiLearning wifi_learning = WifiLearning::kWholeDataSet;  // see WifiLearning
  int online_first_scans = 20;      // kOnline: scans before the first Wi-Fi model
  bool decide_by_log_odds = false;  // the best place's log odds, not its posterior, decide
  double match_log_odds = 0.0;      // with decide_by_log_odds: least log odds of the best place
  // Per-device RSSI offset, estimated online as in [fused] (sensors/rssi_offset.h) and removed
  // from a later session's scans before they become Wi-Fi words and places.
  bool online_rssi_offset = false;
  int rssi_offset_min_common_aps = 5;
  int rssi_offset_min_estimates = 10;

  bool IsValid(std::string* error) const;
  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("match_probability", match_probability,
      "least FABMAP posterior of the best place for its template to become active",
      schema::Unit("").Above(0).AtMost(1));
    v("recency_templates", recency_templates,
      "matches to one of the newest this-many templates re-use it without injection",
      schema::Unit("templates").NonNegative());
    v("recency_s", recency_s, "so do matches to a template made less than this long ago",
      schema::Unit("s").NonNegative());
    v("max_wifi_age_s", max_wifi_age_s, "a Wi-Fi scan older than this counts as absent at a frame",
      schema::Unit("s").NonNegative());
    v("wifi_learning", wifi_learning,
      "Wi-Fi words, tree and unknown world from whole_data_set (every scan, future included) or "
      "online (only the scans seen so far, relearnt as their number doubles)",
      schema::Any());
    v("online_first_scans", online_first_scans,
      "online: scans before the first Wi-Fi model (every frame is a new place until then)",
      schema::Unit("scans").AtLeast(1));
    v("decide_by_log_odds", decide_by_log_odds,
      "the best mapped place becomes active when its log odds against the new place reach "
      "match_log_odds (instead of its posterior reaching match_probability)",
      schema::Any());
    v("match_log_odds", match_log_odds,
      "decide_by_log_odds: least log(p(best place) / p(new place)), nats; 0 is the arg-max, "
      "negative values accept places the new place beats",
      schema::Unit("nats").Within(-1000, 1000));
    v("online_rssi_offset", online_rssi_offset,
      "estimate each later session's RSSI offset to the earlier sessions' places online and "
      "remove it from its scans before they become Wi-Fi words (phones that read several dB "
      "apart)",
      schema::Any());
    v("rssi_offset_min_common_aps", rssi_offset_min_common_aps,
      "APs a scan must share with an earlier session's place to estimate the offset",
      schema::Unit("APs").AtLeast(1));
    v("rssi_offset_min_estimates", rssi_offset_min_estimates,
      "offset estimates of a session before its median is applied",
      schema::Unit("scans").AtLeast(1));
  }
};

// FABMAP localisation (fusion/fabmap): modes, models, words and the benchmark's split.
struct FabmapSettings {
  fabmap::LocaliserSettings localiser;
  fabmap::FeatureOptions features;
  fabmap::VocabularyOptions vocabulary;
  fabmap::VisualModelOptions visual_model;
  FabmapFrontEndOptions front_end;

  bool IsValid(std::string* error) const;
};

// What the FABMAP front end is built from, prepared once per run (PrepareFabmapResources).
struct FabmapResources {
  std::optional<fabmap::TrainedVisualModel> visual;  // to turn images into words
  // The localiser with no places yet (words, trees, unknown world): each front end, and each
  // restore, starts from a copy instead of learning the Wi-Fi tree again. Whole-data-set
  // learning only; online learning builds its own from `scans`.
  std::shared_ptr<const fabmap::Localiser> empty_localiser;
  // Every scan of the data set in order, with the odometry travel before it (online learning
  // uses the first n of them after the n-th scan, never more).
  fabmap::WifiExploration scans;
};

// How a FABMAP front end learnt its Wi-Fi model, for the run's summary.
struct FabmapLearningReport {
  WifiLearning wifi_learning = WifiLearning::kWholeDataSet;
  uint64_t wifi_learned_from_scans = 0;  // scans behind the current Wi-Fi model
  uint64_t wifi_relearnt = 0;            // times the model was (re)built during the run
  uint64_t wifi_tree_scans = 0;          // of the scans, those that learnt the Wi-Fi tree
};

struct FrameDecision {
  ViewDecision view;
  DecisionSource source = DecisionSource::kNew;
  bool recent = false;  // a familiar but recent template: re-used, no injection, not a match
};

// Writing a front end (the extension point for C++ users; fusion/front_end_test.cc has a
// complete example). The pipeline hands a front end every event of the data set in time order
// and applies the decisions it returns:
//  - Frames: return a FrameDecision from OnImage (images are your frames: WantsImages() true)
//    or from OnWifi (scans are your frames), and nothing from the other.
//  - A decision names a template: a new one must take the next id (size() before the call) and
//    set view.is_new; a known one is a re-visit, whose energy is injected into the pose cells
//    unless view.allow_injection is false (set it, and `recent`, for a familiar view that is no
//    loop-closure evidence, such as the template just stored). view.heading_change_rad is the
//    heading now minus the heading the template was stored with, when you know it.
//  - EncodeState/DecodeState make maps saveable and runs resumable: encode every template and
//    everything a later decision depends on; decoding must reject bytes it did not write
//    (sizes, NaN) with an error, never crash. Same inputs must give the same decisions, bit for
//    bit (randomness takes a seed from your options).
//  - Return errors as Status; never print or exit.
// Set [front_end] kind = "custom" and give the session (SessionEnvironment::custom_front_end) or
// the pipeline (FrontEndResources::custom) a factory that makes a fresh front end.
class FrontEnd {
 public:
  virtual ~FrontEnd() = default;
  // A camera image; a decision when images are frames for this front end.
  virtual StatusOr<std::optional<FrameDecision>> OnImage(double time_s, const GrayImage& image) = 0;
  // A Wi-Fi scan; a decision when scans are frames (no camera). By default scans are ignored.
  virtual StatusOr<std::optional<FrameDecision>> OnWifi(const WifiScan&) {
    return std::optional<FrameDecision>();
  }
  virtual void OnCompass(double /*time_s*/, double /*heading_rad*/) {}
  // A barometer reading (hPa). Front ends that track floors fail on a bad reading (time going
  // backwards, pressure outside 100-1,100 hPa); the default ignores it.
  virtual Status OnPressure(double /*time_s*/, double /*pressure_hpa*/) { return Status::Ok(); }
  // A place descriptor computed outside this program for the frame at `time_s` (a live
  // source, or Python's frame-by-frame session); only the descriptor front end takes them.
  virtual StatusOr<std::optional<FrameDecision>> OnDescriptor(
      double /*time_s*/, const std::vector<float>& /*values*/) {
    return Status::Error(
        "this front end takes no descriptors (set [front_end] kind = "
        "\"descriptors\")");
  }
  // The absolute heading the spine should use, if this front end uses a compass (default none).
  virtual std::optional<double> CompassHeading() const { return std::nullopt; }
  virtual bool WantsImages() const = 0;
  // False when the front end needs only an image's time (descriptors computed elsewhere): the
  // replay then passes an empty image instead of loading the file.
  virtual bool NeedsPixels() const { return WantsImages(); }
  virtual uint32_t size() const = 0;  // templates stored
  virtual std::string EncodeState() const = 0;
  virtual Status DecodeState(const std::string& bytes) = 0;
  // A new session (another walk, perhaps another phone) starts at `start_s`; called before each
  // Wi-Fi scan with its session's start (repeats are no news). Default: nothing.
  virtual void OnSessionStart(double /*start_s*/) {}
  // The RSSI offset (dB) removed from each session's scans so far, by session (front ends that
  // estimate one); the last entry is the current session's.
  virtual std::vector<double> RssiOffsetsDb() const { return {}; }
  // APs that revisits added to and dropped from templates ([fused] revisit_update_weight);
  // nothing when off.
  virtual std::optional<std::pair<uint64_t, uint64_t>> RevisitApUpdates() const {
    return std::nullopt;
  }
  // Localisation on a saved map: the templates stored so far were made by another run on
  // another clock, so a match to one of them is never recent. Front ends with a recency rule
  // in seconds must honour this; the default does nothing.
  virtual void SettleForLocalisation() {}
  // Front ends that track floors report them; others return nothing.
  virtual std::optional<FloorReport> floor_report() const { return std::nullopt; }
  // A template's floor relative to the first session's first level, when known.
  virtual std::optional<int> TemplateFloor(uint32_t /*id*/) const { return std::nullopt; }
  // FABMAP front ends say how their Wi-Fi model was learnt; others return nothing.
  virtual std::optional<FabmapLearningReport> fabmap_learning() const { return std::nullopt; }
};

struct FrontEndSettings {
  FrontEndOptions front_end;
  ClassicCameraOptions classic_camera;
  FusedOptions fused;
  KernelCameraOptions camera_12x9;
  WifiMatcherOptions wifi;
  FloorOptions barometer;
  FabmapSettings fabmap;
  DescriptorOptions descriptors;
  // Image sequences (SeqSLAM): `ratslam evaluate --frame-tolerance`, and with recognise_views a
  // sequence recogniser in front of the classic camera and fused front ends.
  SequenceMatcherOptions sequence;
};

// Makes a fresh front end (for kCustom); called again for every restore.
using FrontEndFactory = std::function<std::unique_ptr<FrontEnd>()>;

// What front ends are built from beyond their options, prepared once per run.
struct FrontEndResources {
  FrontEndResources() = default;
  FrontEndResources(std::shared_ptr<const FabmapResources> fabmap_resources)  // NOLINT: implicit
      : fabmap(std::move(fabmap_resources)) {}
  std::shared_ptr<const FabmapResources> fabmap;       // kFabmap (PrepareFabmapResources)
  std::shared_ptr<const DescriptorTable> descriptors;  // kDescriptors
  FrontEndFactory custom;                              // kCustom
};

// The FABMAP front end's models for `dataset`: `visual` (required when the mode uses vision;
// fusion/io/visual_model_file.h loads or trains it) and the Wi-Fi words and tree from an
// exploration of every scan (with odometry travel) when the mode uses Wi-Fi. Reads no file.
// Fails on invalid settings, a missing visual model or an unusable mode.
StatusOr<std::shared_ptr<const FabmapResources>> PrepareFabmapResources(
    const FrontEndSettings& settings, const Dataset& dataset,
    std::optional<fabmap::TrainedVisualModel> visual);

// Fails, before any work, when `dataset` lacks a stream the front end needs: images for a
// camera (classic camera, fused use_camera, FABMAP modes with vision, descriptors), Wi-Fi
// scans for Wi-Fi (fused use_wifi, FABMAP modes with Wi-Fi), a heading stream for the compass
// (fused use_compass). The message names the front end, the missing stream and a shipped config
// that fits the streams the data set has.
Status CheckFrontEndInputs(const FrontEndSettings& settings, const Dataset& dataset);

// kFabmap needs resources.fabmap and kCustom resources.custom
// (returning a front end); without them it throws std::invalid_argument, like the pipeline does
// for invalid options.
std::unique_ptr<FrontEnd> CreateFrontEnd(const FrontEndSettings& settings,
                                         const FrontEndResources& resources = {});

}  // namespace ratslam

#endif  // RATSLAM_FUSION_FRONT_END_H_
