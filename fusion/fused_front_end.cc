// The Wi-Fi RatSLAM paper's front end (section III): 12x9 camera, Wi-Fi fingerprints and a
// compass combined by the b_out rule (eqs. 8-12). See front_end.h.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/byte_buffer.h"
#include "common/circular.h"
#include "fusion/floor_rule.h"
#include "fusion/front_end_internal.h"
#include "sensors/rssi_offset.h"

namespace ratslam::fusion {
namespace front_end_internal {
namespace {

class FusedFrontEnd : public FrontEnd {
 public:
  FusedFrontEnd(const FusedOptions& options, const sensors::KernelCameraOptions& camera,
                const sensors::WifiMatcherOptions& wifi, const FloorOptions& floors)
      : options_(options),
        camera_(camera),
        wifi_(wifi),
        offset_(options.rssi_offset_min_common_aps, options.rssi_offset_min_estimates),
        floors_(floors) {}

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
    if (options_.online_rssi_offset) {
      offset_.Calibrate(wifi_.state().fingerprints, &newest_scan_,
                        walking_ || !options_.rssi_offset_walking_only);
    }
    newest_scan_time_s_ = scan.time_s;
    newest_scan_followed_ = false;
    // One floor vote per scan (a scan re-used by several camera frames votes once).
    if (!newest_scan_.empty()) {
      floors_.Vote(
          [&](const std::vector<uint8_t>& mask) {
            const sensors::WifiMatch m = wifi_.Best(newest_scan_, &mask);
            return std::pair<int64_t, double>(m.id, m.weight);
          },
          wifi_.options().match_threshold);
    }
    if (options_.use_camera) return std::optional<FrameDecision>();  // images are the frames
    return std::optional<FrameDecision>(Decide(scan.time_s, nullptr, &newest_scan_));
  }

  void OnCompass(double, double heading_rad) override { heading_rad_ = heading_rad; }
  void OnWalking(bool walking) override { walking_ = walking; }

  Status OnPressure(double time_s, double pressure_hpa) override {
    return floors_.OnPressure(time_s, pressure_hpa);
  }
  std::optional<int> TemplateFloor(uint32_t id) const override { return floors_.TemplateFloor(id); }
  std::optional<double> CompassHeading() const override {
    return options_.use_compass ? heading_rad_ : std::nullopt;
  }
  bool WantsImages() const override { return options_.use_camera; }
  uint32_t size() const override { return static_cast<uint32_t>(created_time_s_.size()); }
  void SettleForLocalisation() override {
    settled_ = size();
    floors_.SettleForLocalisation();
  }

  void OnSessionStart(double start_s) override {
    floors_.OnSessionStart(start_s);
    if (options_.online_rssi_offset) offset_.OnSessionStart(start_s, size());
  }
  FrontEndReport Report() const override {
    FrontEndReport r;
    if (options_.revisit_update_weight > 0) {
      r.revisit_ap_updates = std::pair(aps_added_, aps_dropped_);
    }
    if (options_.online_rssi_offset) r.rssi_offsets_db = offset_.OffsetsDb();
    r.floors = floors_.Report();
    return r;
  }

  std::string EncodeState() const override {
    ByteWriter w;
    w.Count(camera_.templates().size());
    for (const auto& t : camera_.templates()) w.PodVector(t);
    const sensors::WifiFingerprintMatcher::State& ws = wifi_.state();
    w.Count(ws.bssids.size());
    for (const std::string& b : ws.bssids) w.String(b);
    w.Count(ws.fingerprints.size());
    for (const sensors::Fingerprint& f : ws.fingerprints) {
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
    // Without the option, states keep the format of earlier releases.
    if (options_.online_rssi_offset) offset_.Encode(&w);
    if (options_.revisit_update_weight > 0) {  // likewise
      w.Pod(static_cast<uint8_t>(newest_scan_followed_));
      w.Pod(aps_added_);
      w.Pod(aps_dropped_);
    }
    floors_.Encode(&w);
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
    sensors::WifiFingerprintMatcher::State ws;
    if (!r.Count(8, &n)) return Status::Error(r.error());
    ws.bssids.resize(n);
    for (std::string& b : ws.bssids) {
      if (!r.String(&b)) return Status::Error(r.error());
    }
    if (!r.Count(16, &n)) return Status::Error(r.error());
    ws.fingerprints.resize(n);
    for (sensors::Fingerprint& f : ws.fingerprints) {
      if (!(r.PodVector(&f.ap_ids) && r.PodVector(&f.rssi_dbm))) return Status::Error(r.error());
    }
    std::vector<double> created;
    std::vector<std::optional<double>> headings;
    sensors::Fingerprint newest;
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
    sensors::RssiOffsetTracker offset = offset_;
    if (options_.online_rssi_offset && !offset.Decode(&r, created.size())) {
      return Status::Error(r.error());
    }
    uint8_t followed = 0;
    uint64_t added = 0, dropped = 0;
    if (options_.revisit_update_weight > 0 &&
        !(r.Pod(&followed) && r.Pod(&added) && r.Pod(&dropped))) {
      return Status::Error(r.error());
    }
    if (followed > 1) return Status::Error("fused front-end state: revisit flag is not 0 or 1");
    FloorRule floors = floors_;
    if (!floors.Decode(&r, created.size())) return Status::Error(r.error());
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
    for (const sensors::Fingerprint& f : ws.fingerprints) {
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
    offset_ = std::move(offset);
    newest_scan_followed_ = followed != 0;
    aps_added_ = added;
    aps_dropped_ = dropped;
    floors_ = std::move(floors);
    return Status::Ok();
  }

 private:
  enum class Verdict { kNovel, kFamiliarRecent, kMatch };

  // Eqs. 10-11: a sensor's best match counts when it reaches the threshold and is not recent.
  Verdict Judge(int32_t best, double score, double threshold, double time_s) const {
    if (best < 0 || score < threshold) return Verdict::kNovel;
    const int64_t n = static_cast<int64_t>(created_time_s_.size());
    const bool old_enough = OldEnough(n, best, time_s, created_time_s_[best],
                                      options_.recency_templates, options_.recency_s, settled_);
    return old_enough ? Verdict::kMatch : Verdict::kFamiliarRecent;
  }

  FrameDecision Decide(double time_s, const std::vector<float>* view,
                       const sensors::Fingerprint* scan) {
    const uint32_t n = size();
    Verdict camera_verdict = Verdict::kNovel, wifi_verdict = Verdict::kNovel;
    int32_t camera_best = -1, wifi_best = -1;
    double wifi_best_weight = 0.0;
    // The floor rule, when the barometer has spoken: a flag per template.
    const bool floors = floors_.active();
    std::vector<uint8_t> agrees;
    if (floors) agrees = floors_.BeginFrame(n);
    const std::vector<uint8_t>* allowed = floors ? &agrees : nullptr;
    // Localising on a saved map (SettleForLocalisation): its templates are the reference, and a
    // template made since only stands for a place the map does not hold. A map template that
    // matches wins over one of those, which would otherwise keep the views of a place first seen
    // before it was recognised (e.g. before the phone's RSSI offset was known).
    std::vector<uint8_t> mapped;
    if (settled_ > 0 && n > settled_) {
      mapped = floors ? agrees : std::vector<uint8_t>(n, 1);
      std::fill(mapped.begin() + settled_, mapped.end(), 0);
    }
    if (view) {
      const double threshold = camera_.options().match_threshold;
      sensors::KernelCameraMatch best;
      if (!mapped.empty()) {
        best = camera_.Best(*view, &mapped);
        camera_verdict = Judge(best.id, best.similarity, threshold, time_s);
      }
      if (camera_verdict != Verdict::kMatch) {
        best = camera_.Best(*view, allowed);  // eq. 8
        camera_verdict = Judge(best.id, best.similarity, threshold, time_s);
      }
      camera_best = best.id;
    }
    if (scan && !scan->empty()) {
      // Eq. 9; a best below t_wifi would be novel anyway, so the matcher may prune by it.
      const double threshold = wifi_.options().match_threshold;
      sensors::WifiMatch best;
      if (!mapped.empty()) {
        best = wifi_.Best(*scan, &mapped, threshold);
        wifi_verdict = Judge(best.id, best.weight, threshold, time_s);
      }
      if (wifi_verdict != Verdict::kMatch) {
        best = wifi_.Best(*scan, allowed, threshold);
        wifi_verdict = Judge(best.id, best.weight, threshold, time_s);
      }
      wifi_best = best.id;
      wifi_best_weight = best.weight;
    }
    if (floors && camera_verdict == Verdict::kNovel && wifi_verdict == Verdict::kNovel) {
      // Would a template on another (or an unknown) floor have matched? Then the rule made this
      // template.
      const bool camera_would =
          view && camera_.Best(*view).similarity >= camera_.options().match_threshold;
      const bool wifi_would = scan && !scan->empty() &&
                              wifi_.Best(*scan, nullptr, wifi_.options().match_threshold).id >= 0;
      if (camera_would || wifi_would) floors_.CountRefused();
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
    if (chosen && options_.revisit_update_weight > 0 && scan == &newest_scan_ &&
        !newest_scan_followed_ && wifi_verdict == Verdict::kMatch &&
        static_cast<int32_t>(*chosen) == wifi_best &&
        wifi_best_weight >= options_.revisit_update_weight) {
      // A revisit the scan is sure of: the template follows the APs changed since.
      const sensors::WifiFingerprintMatcher::Update u = wifi_.FollowRevisit(*chosen, *scan);
      aps_added_ += u.added;
      aps_dropped_ += u.dropped;
      newest_scan_followed_ = true;
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
    wifi_.Add(scan ? *scan : sensors::Fingerprint());
    created_time_s_.push_back(time_s);
    headings_.push_back(options_.use_compass ? heading_rad_ : std::nullopt);
    if (options_.online_rssi_offset) offset_.AddTemplate();
    floors_.AddTemplate();
    d.view.template_id = n;
    d.view.is_new = true;
    d.source = DecisionSource::kNew;
    return d;
  }

  FusedOptions options_;
  sensors::KernelCameraMatcher camera_;
  sensors::WifiFingerprintMatcher wifi_;
  std::vector<double> created_time_s_;  // by template
  int64_t settled_ = 0;                 // templates from a saved map (SettleForLocalisation)
  std::vector<std::optional<double>> headings_;  // by template
  sensors::Fingerprint newest_scan_;
  std::optional<double> newest_scan_time_s_;
  bool newest_scan_followed_ = false;  // the newest scan updated a template (revisit_update_weight)
  uint64_t aps_added_ = 0, aps_dropped_ = 0;  // by revisit_update_weight, so far
  std::optional<double> heading_rad_;
  bool walking_ = true;                // before the next scan (OnWalking; true if never told)
  sensors::RssiOffsetTracker offset_;  // [fused] online_rssi_offset: see sensors/rssi_offset.h
  FloorRule floors_;                   // [barometer] use_barometer: see fusion/floor_rule.h
};

}  // namespace

std::unique_ptr<FrontEnd> MakeFusedFrontEnd(const FusedOptions& options,
                                            const sensors::KernelCameraOptions& camera,
                                            const sensors::WifiMatcherOptions& wifi,
                                            const FloorOptions& floors) {
  return std::make_unique<FusedFrontEnd>(options, camera, wifi, floors);
}

}  // namespace front_end_internal
}  // namespace ratslam::fusion
