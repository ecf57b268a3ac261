#include "fusion/front_end.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/byte_buffer.h"
#include "common/circular.h"

namespace ratslam {

std::string ToString(FrontEndKind kind) {
  switch (kind) {
    case FrontEndKind::kClassicCamera:
      return "classic_camera";
    case FrontEndKind::kFused:
      return "fused";
    case FrontEndKind::kFabmap:
      return "fabmap";
  }
  return "unknown";
}

StatusOr<FrontEndKind> FrontEndKindFromString(const std::string& name) {
  if (name == "classic_camera") return FrontEndKind::kClassicCamera;
  if (name == "fused") return FrontEndKind::kFused;
  if (name == "fabmap") return FrontEndKind::kFabmap;
  return Status::Error("unknown front end '" + name + "' (valid: classic_camera, fused, fabmap)");
}

bool FabmapSettings::IsValid(std::string* error) const {
  std::string inner;
  auto check = [&](bool ok, const char* section) {
    if (!ok && error) *error = std::string(section) + "." + inner;
    return ok;
  };
  return check(localiser.localiser.IsValid(&inner), "fabmap") &&
         check(localiser.fabmap.IsValid(&inner), "fabmap_model") &&
         check(localiser.visual_detector.IsValid(&inner), "visual_detector") &&
         check(localiser.wifi_detector.IsValid(&inner), "wifi_detector") &&
         check(features.IsValid(&inner), "visual_words") &&
         check(vocabulary.IsValid(&inner), "vocabulary") &&
         check(visual_model.IsValid(&inner), "visual_model") &&
         check(localiser.wifi_words.IsValid(&inner), "wifi_words") &&
         check(localiser.virtual_wifi.IsValid(&inner), "virtual_wifi") &&
         check(front_end.IsValid(&inner), "fabmap_front_end");
}

bool FabmapFrontEndOptions::IsValid(std::string* error) const {
  if (!(match_probability > 0.0 && match_probability <= 1.0)) {
    if (error) *error = "match_probability: must be in (0, 1]";
    return false;
  }
  if (recency_templates < 0 || !(recency_s >= 0.0) || !(max_wifi_age_s >= 0.0)) {
    if (error) *error = "recency_templates: must not be negative, nor recency_s and max_wifi_age_s";
    return false;
  }
  if (online_first_scans < 1) {
    if (error) *error = "online_first_scans: must be at least 1";
    return false;
  }
  return true;
}

std::string ToString(WifiLearning learning) {
  return learning == WifiLearning::kOnline ? "online" : "whole_data_set";
}

StatusOr<WifiLearning> WifiLearningFromString(const std::string& name) {
  if (name == "whole_data_set") return WifiLearning::kWholeDataSet;
  if (name == "online") return WifiLearning::kOnline;
  return Status::Error("unknown Wi-Fi learning '" + name + "' (whole_data_set or online)");
}

bool FusedOptions::IsValid(std::string* error) const {
  auto fail = [error](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (!use_camera && !use_wifi)
    return fail("use_wifi: at least one of camera and Wi-Fi must be on");
  if (recency_templates < 0) return fail("recency_templates: must not be negative");
  if (!(recency_s >= 0.0) || !std::isfinite(recency_s)) {
    return fail("recency_s: must be a non-negative number");
  }
  if (!(max_wifi_age_s >= 0.0)) return fail("max_wifi_age_s: must not be negative");
  return true;
}

namespace {

template <typename T>
bool AllFinite(const std::vector<T>& values) {
  return std::all_of(values.begin(), values.end(), [](T v) { return std::isfinite(v); });
}
bool FiniteOrAbsent(const std::optional<double>& v) { return !v || std::isfinite(*v); }

GrayImageView ViewOf(const GrayImage& image) {
  return {image.width, image.height, image.width, image.pixels.data()};
}

class ClassicCameraFrontEnd : public FrontEnd {
 public:
  explicit ClassicCameraFrontEnd(const ClassicCameraOptions& options) : matcher_(options) {}

  StatusOr<std::optional<FrameDecision>> OnImage(double time_s, const GrayImage& image) override {
    StatusOr<ViewDecision> view = matcher_.Observe(ViewOf(image), time_s);
    if (!view.ok()) return view.status();
    FrameDecision d;
    d.view = view.value();
    d.source = d.view.is_new ? DecisionSource::kNew : DecisionSource::kCamera;
    return std::optional<FrameDecision>(d);
  }
  StatusOr<std::optional<FrameDecision>> OnWifi(const WifiScan&) override {
    return std::optional<FrameDecision>();
  }
  void OnCompass(double, double) override {}
  std::optional<double> CompassHeading() const override { return std::nullopt; }
  bool WantsImages() const override { return true; }
  uint32_t size() const override { return matcher_.size(); }

  std::string EncodeState() const override {
    ByteWriter w;
    w.Pod(matcher_.state().template_count);
    w.PodVector(matcher_.state().templates);
    return std::move(w.bytes());
  }
  Status DecodeState(const std::string& bytes) override {
    ByteReader r(bytes, "classic camera state");
    ClassicCameraMatcher::State state;
    if (!(r.Pod(&state.template_count) && r.PodVector(&state.templates) && r.AtEnd())) {
      return Status::Error(r.error().empty() ? "classic camera state: trailing bytes" : r.error());
    }
    return matcher_.SetState(std::move(state));
  }

 private:
  ClassicCameraMatcher matcher_;
};

class FusedFrontEnd : public FrontEnd {
 public:
  FusedFrontEnd(const FusedOptions& options, const KernelCameraOptions& camera,
                const WifiMatcherOptions& wifi)
      : options_(options), camera_(camera), wifi_(wifi) {}

  StatusOr<std::optional<FrameDecision>> OnImage(double time_s, const GrayImage& image) override {
    if (!options_.use_camera) return std::optional<FrameDecision>();
    StatusOr<std::vector<float>> view = camera_.MakeTemplate(ViewOf(image));
    if (!view.ok()) return view.status();
    // The newest scan, if fresh enough, is this frame's Wi-Fi observation.
    const bool fresh = options_.use_wifi && newest_scan_time_s_ &&
                       time_s - *newest_scan_time_s_ <= options_.max_wifi_age_s;
    return std::optional<FrameDecision>(
        Decide(time_s, &view.value(), fresh ? &newest_scan_ : nullptr));
  }

  StatusOr<std::optional<FrameDecision>> OnWifi(const WifiScan& scan) override {
    if (!options_.use_wifi) return std::optional<FrameDecision>();
    std::vector<std::pair<std::string, double>> readings;
    readings.reserve(scan.readings.size());
    for (const WifiReading& r : scan.readings) readings.emplace_back(r.bssid, r.rssi_dbm);
    newest_scan_ = wifi_.MakeFingerprint(readings);
    newest_scan_time_s_ = scan.time_s;
    if (options_.use_camera) return std::optional<FrameDecision>();  // images are the frames
    return std::optional<FrameDecision>(Decide(scan.time_s, nullptr, &newest_scan_));
  }

  void OnCompass(double, double heading_rad) override { heading_rad_ = heading_rad; }
  std::optional<double> CompassHeading() const override {
    return options_.use_compass ? heading_rad_ : std::nullopt;
  }
  bool WantsImages() const override { return options_.use_camera; }
  uint32_t size() const override { return static_cast<uint32_t>(created_time_s_.size()); }

  std::string EncodeState() const override {
    ByteWriter w;
    w.Count(camera_.templates().size());
    for (const auto& t : camera_.templates()) w.PodVector(t);
    const WifiFingerprintMatcher::State& ws = wifi_.state();
    w.Count(ws.bssids.size());
    for (const std::string& b : ws.bssids) w.String(b);
    w.Count(ws.fingerprints.size());
    for (const Fingerprint& f : ws.fingerprints) {
      w.PodVector(f.ap_ids);
      w.PodVector(f.rssi_dbm);
    }
    w.PodVector(created_time_s_);
    w.Count(headings_.size());
    for (const auto& h : headings_) w.Optional(h);
    w.PodVector(newest_scan_.ap_ids);
    w.PodVector(newest_scan_.rssi_dbm);
    w.Optional(newest_scan_time_s_);
    w.Optional(heading_rad_);
    return std::move(w.bytes());
  }

  Status DecodeState(const std::string& bytes) override {
    ByteReader r(bytes, "fused front-end state");
    size_t n = 0;
    std::vector<std::vector<float>> camera;
    if (!r.Count(8, &n)) return Status::Error(r.error());
    camera.resize(n);
    for (auto& t : camera) {
      if (!r.PodVector(&t)) return Status::Error(r.error());
    }
    WifiFingerprintMatcher::State ws;
    if (!r.Count(8, &n)) return Status::Error(r.error());
    ws.bssids.resize(n);
    for (std::string& b : ws.bssids) {
      if (!r.String(&b)) return Status::Error(r.error());
    }
    if (!r.Count(16, &n)) return Status::Error(r.error());
    ws.fingerprints.resize(n);
    for (Fingerprint& f : ws.fingerprints) {
      if (!(r.PodVector(&f.ap_ids) && r.PodVector(&f.rssi_dbm))) return Status::Error(r.error());
    }
    std::vector<double> created;
    std::vector<std::optional<double>> headings;
    Fingerprint newest;
    std::optional<double> newest_time, heading;
    if (!(r.PodVector(&created) && r.Count(9, &n))) return Status::Error(r.error());
    headings.resize(n);
    for (auto& h : headings) {
      if (!r.Optional(&h)) return Status::Error(r.error());
    }
    if (!(r.PodVector(&newest.ap_ids) && r.PodVector(&newest.rssi_dbm) &&
          r.Optional(&newest_time) && r.Optional(&heading))) {
      return Status::Error(r.error());
    }
    if (!r.AtEnd()) return Status::Error("fused front-end state: trailing bytes");
    if (camera.size() != created.size() || ws.fingerprints.size() != created.size() ||
        headings.size() != created.size()) {
      return Status::Error("fused front-end state: sensor template counts differ");
    }
    if (!AllFinite(created) || !std::all_of(headings.begin(), headings.end(), FiniteOrAbsent) ||
        !FiniteOrAbsent(newest_time) || !FiniteOrAbsent(heading) || !AllFinite(newest.rssi_dbm) ||
        newest.ap_ids.size() != newest.rssi_dbm.size() ||
        std::any_of(newest.ap_ids.begin(), newest.ap_ids.end(),
                    [&ws](uint32_t id) { return id >= ws.bssids.size(); })) {
      return Status::Error(
          "fused front-end state: a time, heading or RSSI is not finite, or the newest scan "
          "names an unknown access point");
    }
    for (const Fingerprint& f : ws.fingerprints) {
      if (!AllFinite(f.rssi_dbm)) {
        return Status::Error("fused front-end state: a fingerprint RSSI is not finite");
      }
    }
    RATSLAM_RETURN_IF_ERROR(camera_.SetTemplates(std::move(camera)));
    RATSLAM_RETURN_IF_ERROR(wifi_.SetState(std::move(ws)));
    created_time_s_ = std::move(created);
    headings_ = std::move(headings);
    newest_scan_ = std::move(newest);
    newest_scan_time_s_ = newest_time;
    heading_rad_ = heading;
    return Status::Ok();
  }

 private:
  enum class Verdict { kNovel, kFamiliarRecent, kMatch };

  // Eqs. 10-11: a sensor's best match counts when it reaches the threshold and is not recent.
  Verdict Judge(int32_t best, double score, double threshold, double time_s) const {
    if (best < 0 || score < threshold) return Verdict::kNovel;
    const int64_t n = static_cast<int64_t>(created_time_s_.size());
    const bool old_enough = n - best >= options_.recency_templates &&
                            time_s - created_time_s_[best] >= options_.recency_s;
    return old_enough ? Verdict::kMatch : Verdict::kFamiliarRecent;
  }

  FrameDecision Decide(double time_s, const std::vector<float>* view, const Fingerprint* scan) {
    const uint32_t n = size();
    Verdict camera_verdict = Verdict::kNovel, wifi_verdict = Verdict::kNovel;
    int32_t camera_best = -1, wifi_best = -1;
    if (view) {
      const KernelCameraMatch best = camera_.Best(*view);  // eq. 8
      camera_best = best.id;
      camera_verdict = Judge(best.id, best.similarity, camera_.options().match_threshold, time_s);
    }
    if (scan && !scan->empty()) {
      const WifiMatch best = wifi_.Best(*scan);  // eq. 9
      wifi_best = best.id;
      wifi_verdict = Judge(best.id, best.weight, wifi_.options().match_threshold, time_s);
    }
    FrameDecision d;
    d.view.time_s = time_s;
    std::optional<uint32_t> chosen;
    // Eq. 12: camera first, then Wi-Fi; then a familiar recent template; else new.
    if (camera_verdict == Verdict::kMatch) {
      chosen = camera_best;
      d.source = DecisionSource::kCamera;
    } else if (wifi_verdict == Verdict::kMatch) {
      chosen = wifi_best;
      d.source = DecisionSource::kWifi;
    } else if (camera_verdict == Verdict::kFamiliarRecent) {
      chosen = camera_best;
      d.source = DecisionSource::kCamera;
      d.recent = true;
    } else if (wifi_verdict == Verdict::kFamiliarRecent) {
      chosen = wifi_best;
      d.source = DecisionSource::kWifi;
      d.recent = true;
    }
    if (chosen) {
      d.view.template_id = *chosen;
      d.view.is_new = false;
      d.view.allow_injection = !d.recent;
      const std::optional<double>& stored = headings_[*chosen];
      if (options_.use_compass && heading_rad_ && stored) {
        // Eq. 2 gives theta_j - theta_t; the spine wants the change since the template.
        d.view.heading_change_rad = WrapAngle(*heading_rad_ - *stored);
      }
      return d;
    }
    // Both sensors say novel: a new joint template.
    camera_.Add(view ? *view : std::vector<float>());
    wifi_.Add(scan ? *scan : Fingerprint());
    created_time_s_.push_back(time_s);
    headings_.push_back(options_.use_compass ? heading_rad_ : std::nullopt);
    d.view.template_id = n;
    d.view.is_new = true;
    d.source = DecisionSource::kNew;
    return d;
  }

  FusedOptions options_;
  KernelCameraMatcher camera_;
  WifiFingerprintMatcher wifi_;
  std::vector<double> created_time_s_;           // by template
  std::vector<std::optional<double>> headings_;  // by template
  Fingerprint newest_scan_;
  std::optional<double> newest_scan_time_s_;
  std::optional<double> heading_rad_;
};

class FabmapFrontEnd : public FrontEnd {
 public:
  FabmapFrontEnd(const FabmapSettings& settings, std::shared_ptr<const FabmapResources> resources)
      : settings_(settings), resources_(std::move(resources)) {
    if (!resources_ || (!online() && !resources_->empty_localiser)) {
      throw std::invalid_argument("the FABMAP front end needs PrepareFabmapResources' models");
    }
    Reset();
  }

  StatusOr<std::optional<FrameDecision>> OnImage(double time_s, const GrayImage& image) override {
    if (!fabmap::UsesVision(mode())) return std::optional<FrameDecision>();
    auto words = fabmap::ImageWords(*resources_->visual, image);
    if (!words.ok()) return words.status();
    fabmap::Query q;
    q.visual = *std::move(words);
    if (fabmap::UsesWifi(mode()) && newest_scan_time_s_ &&
        time_s - *newest_scan_time_s_ <= settings_.front_end.max_wifi_age_s) {
      q.wifi = newest_scan_;
    }
    return Decide(time_s, std::move(q));
  }

  StatusOr<std::optional<FrameDecision>> OnWifi(const WifiScan& scan) override {
    if (!fabmap::UsesWifi(mode())) return std::optional<FrameDecision>();
    newest_scan_ = scan.readings;
    newest_scan_time_s_ = scan.time_s;
    ++scans_seen_;
    if (online() && scans_seen_ >= NextRelearn()) RATSLAM_RETURN_IF_ERROR(Relearn(scans_seen_));
    if (fabmap::UsesVision(mode())) return std::optional<FrameDecision>();  // images are frames
    fabmap::Query q;
    q.wifi = scan.readings;
    return Decide(scan.time_s, std::move(q));
  }

  void OnCompass(double, double) override {}
  std::optional<double> CompassHeading() const override { return std::nullopt; }
  bool WantsImages() const override { return fabmap::UsesVision(mode()); }
  uint32_t size() const override { return static_cast<uint32_t>(places_.size()); }
  std::optional<FabmapLearningReport> fabmap_learning() const override {
    return FabmapLearningReport{
        settings_.front_end.wifi_learning,
        online() ? learned_from_ : static_cast<uint64_t>(resources_->scans.scans.size()),
        online() ? relearnt_ : 1};
  }

  std::string EncodeState() const override {
    ByteWriter w;
    w.Count(places_.size());
    for (size_t i = 0; i < places_.size(); ++i) {
      w.Pod(created_time_s_[i]);
      w.PodVector(places_[i].visual);
      w.Bool(places_[i].wifi.has_value());
      const auto& readings = places_[i].wifi ? *places_[i].wifi : std::vector<WifiReading>();
      w.Count(readings.size());
      for (const WifiReading& r : readings) {
        w.String(r.bssid);
        w.Pod(r.rssi_dbm);
      }
    }
    w.Optional(newest_scan_time_s_);
    w.Count(newest_scan_.size());
    for (const WifiReading& r : newest_scan_) {
      w.String(r.bssid);
      w.Pod(r.rssi_dbm);
    }
    if (online()) {  // whole-data-set states keep the format of earlier releases
      w.Pod(scans_seen_);
      w.Pod(learned_from_);
      w.Pod(relearnt_);
    }
    return std::move(w.bytes());
  }

  Status DecodeState(const std::string& bytes) override {
    ByteReader r(bytes, "FABMAP front-end state");
    auto readings = [&r](std::vector<WifiReading>* out) {
      size_t n = 0;
      if (!r.Count(9, &n)) return false;
      out->resize(n);
      for (WifiReading& x : *out) {
        if (!(r.String(&x.bssid) && r.Pod(&x.rssi_dbm))) return false;
      }
      return true;
    };
    size_t count = 0;
    std::vector<double> times;
    std::vector<fabmap::Query> places;
    bool ok = r.Count(8 + 8 + 1 + 8, &count);
    for (size_t i = 0; ok && i < count; ++i) {
      double t = 0.0;
      fabmap::Query q;
      bool has_wifi = false;
      std::vector<WifiReading> scan;
      ok = r.Pod(&t) && r.PodVector(&q.visual) && r.Bool(&has_wifi) && readings(&scan);
      if (has_wifi) q.wifi = std::move(scan);
      times.push_back(t);
      places.push_back(std::move(q));
    }
    std::optional<double> newest_time;
    std::vector<WifiReading> newest;
    uint64_t scans_seen = 0, learned_from = 0, relearnt = 0;
    ok = ok && r.Optional(&newest_time) && readings(&newest) &&
         (!online() || (r.Pod(&scans_seen) && r.Pod(&learned_from) && r.Pod(&relearnt))) &&
         (r.AtEnd() || r.Fail("trailing bytes"));
    if (!ok) return Status::Error(r.error());
    if (online() &&
        (scans_seen > resources_->scans.scans.size() || learned_from > scans_seen ||
         (learned_from > 0 &&
          learned_from < static_cast<uint64_t>(settings_.front_end.online_first_scans)))) {
      return Status::Error("FABMAP front-end state: scan counts do not fit the data set");
    }
    auto readings_ok = [](const std::vector<WifiReading>& scan) {
      return std::all_of(scan.begin(), scan.end(),
                         [](const WifiReading& x) { return std::isfinite(x.rssi_dbm); });
    };
    if (!AllFinite(times) || !FiniteOrAbsent(newest_time) || !readings_ok(newest) ||
        !std::all_of(places.begin(), places.end(),
                     [&](const fabmap::Query& q) { return !q.wifi || readings_ok(*q.wifi); })) {
      return Status::Error("FABMAP front-end state: a time or RSSI is not finite");
    }
    Reset();
    places_ = std::move(places);
    created_time_s_ = std::move(times);
    newest_scan_time_s_ = newest_time;
    newest_scan_ = std::move(newest);
    scans_seen_ = scans_seen;
    relearnt_ = relearnt;
    if (online()) {
      // The model is a function of the scans it learnt from: rebuild it, then re-add the places.
      if (learned_from > 0) RATSLAM_RETURN_IF_ERROR(Relearn(learned_from, /*count=*/false));
    } else {
      for (const fabmap::Query& place : places_) {
        RATSLAM_RETURN_IF_ERROR(localiser_->AddPlace(place));
      }
    }
    return Status::Ok();
  }

 private:
  fabmap::FabmapMode mode() const { return settings_.localiser.localiser.mode; }

  // Online learning applies to modes that use Wi-Fi (the visual model never comes from the run).
  bool online() const {
    return settings_.front_end.wifi_learning == WifiLearning::kOnline && fabmap::UsesWifi(mode());
  }

  void Reset() {
    localiser_ =
        online() ? nullptr : std::make_unique<fabmap::Localiser>(*resources_->empty_localiser);
    places_.clear();
    created_time_s_.clear();
    scans_seen_ = learned_from_ = relearnt_ = 0;
  }

  // Online learning: the first model after online_first_scans scans, then one each time the
  // number of scans seen doubles (O(n log n) learning over a run of n scans).
  uint64_t NextRelearn() const {
    const uint64_t first = static_cast<uint64_t>(settings_.front_end.online_first_scans);
    return learned_from_ == 0 ? first : 2 * learned_from_;
  }

  // Builds the Wi-Fi model from the first `scans` scans of the data set and maps every place
  // again in it.
  Status Relearn(uint64_t scans, bool count = true) {
    const fabmap::WifiExploration& all = resources_->scans;
    fabmap::WifiExploration seen;
    seen.scans.assign(all.scans.begin(), all.scans.begin() + scans);
    seen.travelled_m.assign(all.travelled_m.begin(), all.travelled_m.begin() + scans);
    seen.time_s.assign(all.time_s.begin(), all.time_s.begin() + scans);
    auto localiser = fabmap::Localiser::Create(
        settings_.localiser, resources_->visual ? &resources_->visual->model : nullptr, seen);
    if (!localiser.ok()) return localiser.status().WithContext("FABMAP online Wi-Fi learning");
    for (const fabmap::Query& place : places_) {
      RATSLAM_RETURN_IF_ERROR((*localiser)->AddPlace(place));
    }
    localiser_ = std::move(localiser).value();
    learned_from_ = scans;
    if (count) ++relearnt_;
    return Status::Ok();
  }

  StatusOr<std::optional<FrameDecision>> Decide(double time_s, fabmap::Query q) {
    if (!localiser_) {  // online, before the first model: every frame is a new place
      places_.push_back(std::move(q));
      created_time_s_.push_back(time_s);
      FrameDecision d;
      d.view.time_s = time_s;
      d.view.template_id = static_cast<uint32_t>(places_.size() - 1);
      d.view.is_new = true;
      d.source = DecisionSource::kNew;
      return std::optional<FrameDecision>(d);
    }
    const fabmap::LocalisationResult r = localiser_->Localise(q);
    FrameDecision d;
    d.view.time_s = time_s;
    d.source = fabmap::UsesVision(mode()) ? DecisionSource::kCamera : DecisionSource::kWifi;
    const int64_t n = static_cast<int64_t>(places_.size());
    if (r.best_place >= 0 && r.best_probability >= settings_.front_end.match_probability) {
      const bool old_enough =
          n - r.best_place >= settings_.front_end.recency_templates &&
          time_s - created_time_s_[r.best_place] >= settings_.front_end.recency_s;
      d.view.template_id = static_cast<uint32_t>(r.best_place);
      d.view.is_new = false;
      d.recent = !old_enough;
      d.view.allow_injection = old_enough;
      return std::optional<FrameDecision>(d);
    }
    RATSLAM_RETURN_IF_ERROR(localiser_->AddPlace(q));
    places_.push_back(std::move(q));
    created_time_s_.push_back(time_s);
    d.view.template_id = static_cast<uint32_t>(n);
    d.view.is_new = true;
    d.source = DecisionSource::kNew;
    return std::optional<FrameDecision>(d);
  }

  FabmapSettings settings_;
  std::shared_ptr<const FabmapResources> resources_;
  std::unique_ptr<fabmap::Localiser> localiser_;
  std::vector<fabmap::Query> places_;
  std::vector<double> created_time_s_;
  std::vector<WifiReading> newest_scan_;
  std::optional<double> newest_scan_time_s_;
  uint64_t scans_seen_ = 0;    // Wi-Fi scans received
  uint64_t learned_from_ = 0;  // online: scans behind the current model (0: none yet)
  uint64_t relearnt_ = 0;      // online: models built so far
};

}  // namespace

StatusOr<std::shared_ptr<const FabmapResources>> PrepareFabmapResources(
    const FrontEndSettings& settings, const Dataset& dataset, ImageLoader& images) {
  const FabmapSettings& f = settings.fabmap;
  std::string error;
  if (!f.IsValid(&error)) return Status::Error("FABMAP settings: " + error);
  auto resources = std::make_shared<FabmapResources>();
  const fabmap::FabmapMode mode = f.localiser.localiser.mode;
  if (fabmap::UsesVision(mode)) {
    auto model = fabmap::LoadOrTrainVisualModel(f.visual_model, f.features, f.vocabulary,
                                                f.localiser.chow_liu, images, nullptr);
    if (!model.ok()) {
      return model.status().WithContext("FABMAP mode " + fabmap::ToString(mode));
    }
    resources->visual = *std::move(model);
  }
  fabmap::WifiExploration exploration;
  if (fabmap::UsesWifi(mode)) {
    // Travel at each scan from the odometry (speed held from one row's time to the next's).
    double travelled = 0.0, last_time = 0.0;
    size_t k = 0;
    for (const WifiScan& scan : dataset.wifi) {
      while (k < dataset.odometry.size() && dataset.odometry[k].time_s <= scan.time_s) {
        travelled += std::abs(dataset.odometry[k].forward_speed_m_per_s) *
                     std::max(0.0, dataset.odometry[k].time_s - last_time);
        last_time = dataset.odometry[k].time_s;
        ++k;
      }
      exploration.scans.push_back(scan.readings);
      exploration.travelled_m.push_back(travelled);
      exploration.time_s.push_back(scan.time_s);
    }
  }
  if (f.front_end.wifi_learning == WifiLearning::kWholeDataSet || !fabmap::UsesWifi(mode)) {
    auto localiser = fabmap::Localiser::Create(
        f.localiser, resources->visual ? &resources->visual->model : nullptr, exploration);
    if (!localiser.ok()) return localiser.status();
    resources->empty_localiser = std::move(localiser).value();
  }
  resources->scans = std::move(exploration);
  return std::shared_ptr<const FabmapResources>(std::move(resources));
}

std::unique_ptr<FrontEnd> CreateFrontEnd(const FrontEndSettings& s,
                                         std::shared_ptr<const FabmapResources> fabmap) {
  switch (s.front_end.kind) {
    case FrontEndKind::kClassicCamera:
      return std::make_unique<ClassicCameraFrontEnd>(s.classic_camera);
    case FrontEndKind::kFused:
      return std::make_unique<FusedFrontEnd>(s.fused, s.camera_12x9, s.wifi);
    case FrontEndKind::kFabmap:
      return std::make_unique<FabmapFrontEnd>(s.fabmap, std::move(fabmap));
  }
  return nullptr;
}

}  // namespace ratslam
