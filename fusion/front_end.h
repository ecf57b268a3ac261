// Front ends decide which local view is active. The replay pipeline hands them every event; a
// front end answers with a frame decision when an event makes a frame (a camera image, or a
// Wi-Fi scan when no camera is used).
//
// kClassicCamera: the OpenRatSLAM camera matcher (sensors/classic_camera_matcher.h).
// kFused: the Wi-Fi RatSLAM paper's camera, Wi-Fi and compass front end (fusion/fused_options.h).
// kFabmap: FABMAP decides the active view (fusion/fabmap_front_end_options.h).
// Floors from the barometer for the fused and FABMAP front ends: fusion/fused_options.h.
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
#include "dataset/dataset.h"
#include "dataset/image_loader.h"
#include "fusion/descriptor_table.h"
#include "fusion/fabmap_front_end_options.h"
#include "fusion/fused_options.h"
#include "ratslam/local_view_cells.h"
#include "ratslam/records.h"
#include "sensors/classic_camera_matcher.h"
#include "sensors/kernel_camera_matcher.h"
#include "sensors/sequence_matcher.h"
#include "sensors/wifi_fingerprint_matcher.h"

namespace ratslam::fusion {

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
// What a front end reports for a run's summary; each part only from the front ends it concerns.
struct FrontEndReport {
  // The RSSI offset (dB) removed from each session's scans so far, by session (front ends that
  // estimate one); the last entry is the current session's.
  std::vector<double> rssi_offsets_db;
  // APs that revisits added to and dropped from templates ([fused] revisit_update_weight).
  std::optional<std::pair<uint64_t, uint64_t>> revisit_ap_updates;
  // Floors, from front ends that track them.
  std::optional<FloorReport> floors;
  // How a FABMAP front end's Wi-Fi model was learnt.
  std::optional<FabmapLearningReport> fabmap_learning;
};

// What a first pass over a data set taught a front end (FrontEnd::Learnt and Calibrate).
struct FrontEndCalibration {
  // The FABMAP front end's earlier-session threshold (nats); none when the pass verified fewer
  // than learn_min_revisits revisits.
  std::optional<double> earlier_session_log_odds;
  uint64_t verified_revisits = 0;
};

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
  // Whether the walker moved just before the next Wi-Fi scan (odometry travelled within the
  // PDR's max_step_interval_s); called before each scan in a replay. Default: nothing.
  virtual void OnWalking(bool /*walking*/) {}
  // A revisit verified outside the front end (the Wi-Fi sequence loop closer's inliers): the
  // Wi-Fi scan at `current_time_s` shows the place of the earlier scan at `past_time_s`. Front
  // ends that learn from revisits use it; by default it is ignored.
  virtual void OnVerifiedRevisit(double /*current_time_s*/, double /*past_time_s*/) {}
  // Replay's calibration ([fabmap_front_end] calibrate_earlier_session_log_odds): what this
  // front end learnt over a first pass, and the same handed to a fresh front end of the second
  // pass before its first frame. Front ends that learn nothing return none and refuse one.
  virtual std::optional<FrontEndCalibration> Learnt() const { return std::nullopt; }
  virtual Status Calibrate(const FrontEndCalibration& /*calibration*/) {
    return Status::Error("this front end takes no calibration");
  }
  // What this front end has to say about the run so far, for summaries (default: nothing).
  virtual FrontEndReport Report() const { return {}; }
  // Localisation on a saved map: the templates stored so far were made by another run on
  // another clock, so a match to one of them is never recent. Front ends with a recency rule
  // in seconds must honour this; the default does nothing.
  virtual void SettleForLocalisation() {}
  // A template's floor relative to the first session's first level, when known.
  virtual std::optional<int> TemplateFloor(uint32_t /*id*/) const { return std::nullopt; }
};

struct FrontEndSettings {
  FrontEndOptions front_end;
  sensors::ClassicCameraOptions classic_camera;
  FusedOptions fused;
  sensors::KernelCameraOptions camera_12x9;
  sensors::WifiMatcherOptions wifi;
  FloorOptions barometer;
  FabmapSettings fabmap;
  DescriptorOptions descriptors;
  // Image sequences (SeqSLAM): `ratslam evaluate --frame-tolerance`, and with recognise_views a
  // sequence recogniser in front of the classic camera and fused front ends.
  sensors::SequenceMatcherOptions sequence;
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
// io/visual_model_file.h loads or trains it) and the Wi-Fi words and tree from an
// exploration of every scan (with odometry travel) when the mode uses Wi-Fi. Reads no file.
// Fails on invalid settings, a missing visual model or an unusable mode.
StatusOr<std::shared_ptr<const FabmapResources>> PrepareFabmapResources(
    const FrontEndSettings& settings, const dataset::Dataset& dataset,
    std::optional<fabmap::TrainedVisualModel> visual);

// Fails, before any work, when `dataset` lacks a stream the front end needs: images for a
// camera (classic camera, fused use_camera, FABMAP modes with vision, descriptors), Wi-Fi
// scans for Wi-Fi (fused use_wifi, FABMAP modes with Wi-Fi), a heading stream for the compass
// (fused use_compass). The message names the front end, the missing stream and a shipped config
// that fits the streams the data set has.
Status CheckFrontEndInputs(const FrontEndSettings& settings, const dataset::Dataset& dataset);

// kFabmap needs resources.fabmap and kCustom resources.custom
// (returning a front end); without them it throws std::invalid_argument, like the pipeline does
// for invalid options.
std::unique_ptr<FrontEnd> CreateFrontEnd(const FrontEndSettings& settings,
                                         const FrontEndResources& resources = {});

}  // namespace ratslam::fusion

#endif  // RATSLAM_FUSION_FRONT_END_H_
