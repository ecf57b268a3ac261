// The Wi-Fi RatSLAM paper's front end (section III): 12x9 camera, Wi-Fi fingerprints and a
// compass combined by the b_out rule (eqs. 8-12). See front_end.h.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/byte_buffer.h"
#include "common/circular.h"
#include "common/median.h"
#include "fusion/front_end_internal.h"

namespace ratslam {
namespace front_end_internal {
namespace {

class FusedFrontEnd : public FrontEnd {
 public:
  FusedFrontEnd(const FusedOptions& options, const KernelCameraOptions& camera,
                const WifiMatcherOptions& wifi, const BarometerOptions& barometer)
      : options_(options),
        camera_(camera),
        wifi_(wifi),
        barometer_(barometer),
        tracker_(barometer) {
    std::string error;
    if (options_.use_barometer && !barometer_.IsValid(&error)) {
      throw std::invalid_argument("[barometer] " + error);
    }
  }

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
    if (options_.online_rssi_offset) RemoveRssiOffset(&newest_scan_);
    newest_scan_time_s_ = scan.time_s;
    if (options_.use_camera) return std::optional<FrameDecision>();  // images are the frames
    return std::optional<FrameDecision>(Decide(scan.time_s, nullptr, &newest_scan_));
  }

  void OnCompass(double, double heading_rad) override { heading_rad_ = heading_rad; }

  Status OnPressure(double time_s, double pressure_hpa) override {
    if (!options_.use_barometer) return Status::Ok();
    StatusOr<FloorEstimate> e = tracker_.Add({time_s, pressure_hpa});
    if (!e.ok()) return e.status();
    ++pressure_readings_;
    // Before the first dwell a session is on its first level (level 0): walks start standing.
    current_level_ = e->in_transit ? kUnknownFloor : std::max(e->level, 0);
    // Level floors, renumbered only when a level is added (level 0, floor 0, from the start).
    std::vector<int32_t>& floors = session_level_floors_[floor_session_];
    if (floors.size() != std::max<size_t>(tracker_.levels(), 1)) {
      const std::vector<int> now = tracker_.LevelFloors();
      floors.assign(now.begin(), now.end());
      if (floors.empty()) floors.push_back(0);
    }
    return Status::Ok();
  }
  std::optional<FloorReport> floor_report() const override {
    if (!options_.use_barometer || pressure_readings_ == 0) return std::nullopt;
    FloorReport r;
    r.pressure_readings = pressure_readings_;
    r.floor_changes = floor_changes_before_ + tracker_.floor_changes();
    r.frames_floor_unknown = frames_floor_unknown_;
    r.new_templates_by_floor_rule = new_templates_by_floor_rule_;
    r.templates_with_floor = static_cast<uint64_t>(std::count_if(
        template_level_.begin(), template_level_.end(), [](int32_t l) { return l >= 0; }));
    r.session_floor_offsets.assign(session_offset_.begin(), session_offset_.end());
    r.floor_offset_changes = floor_offset_changes_;
    return r;
  }
  std::optional<int> TemplateFloor(uint32_t id) const override {
    if (id >= template_level_.size() || template_level_[id] < 0) return std::nullopt;
    return MapFloor(template_session_[id], template_level_[id]);
  }
  std::optional<double> CompassHeading() const override {
    return options_.use_compass ? heading_rad_ : std::nullopt;
  }
  bool WantsImages() const override { return options_.use_camera; }
  uint32_t size() const override { return static_cast<uint32_t>(created_time_s_.size()); }
  void SettleForLocalisation() override {
    settled_ = size();
    if (options_.use_barometer) {  // the walk to localise is a session of its own
      NewFloorSession();
      floor_session_start_s_.reset();
    }
  }

  void OnSessionStart(double start_s) override {
    if (options_.use_barometer && floor_session_start_s_ != start_s) {
      if (floor_session_start_s_) NewFloorSession();
      floor_session_start_s_ = start_s;
    }
    if (!options_.online_rssi_offset || (session_start_s_ && *session_start_s_ == start_s)) return;
    if (session_start_s_) offsets_db_.push_back(CurrentOffset());
    session_start_s_ = start_s;
    templates_before_session_ = size();
    offset_estimates_db_.clear();
  }
  std::vector<double> RssiOffsetsDb() const override {
    if (!options_.online_rssi_offset) return {};
    std::vector<double> all = offsets_db_;
    all.push_back(CurrentOffset());
    return all;
  }

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
    if (options_.online_rssi_offset) {  // without it, states keep the format of earlier releases
      w.Optional(session_start_s_);
      w.Pod(templates_before_session_);
      w.PodVector(offset_estimates_db_);
      w.PodVector(offsets_db_);
      w.PodVector(calibrated_);
    }
    if (options_.use_barometer) {  // likewise
      tracker_.Encode(&w);
      w.Pod(pressure_readings_);
      w.Pod(floor_changes_before_);
      w.Pod(current_level_);
      w.Pod(floor_session_);
      w.Optional(floor_session_start_s_);
      w.Count(session_level_floors_.size());
      for (const auto& floors : session_level_floors_) w.PodVector(floors);
      w.PodVector(session_offset_);
      w.PodVector(votes_);
      w.Pod(floor_offset_changes_);
      w.PodVector(template_session_);
      w.PodVector(template_level_);
      w.Pod(frames_floor_unknown_);
      w.Pod(new_templates_by_floor_rule_);
    }
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
    std::optional<double> session_start;
    uint32_t before_session = 0;
    std::vector<double> estimates, offsets;
    std::vector<uint8_t> calibrated;
    if (options_.online_rssi_offset &&
        !(r.Optional(&session_start) && r.Pod(&before_session) && r.PodVector(&estimates) &&
          r.PodVector(&offsets) && r.PodVector(&calibrated))) {
      return Status::Error(r.error());
    }
    FloorState floors(barometer_);
    if (options_.use_barometer && !DecodeFloors(&r, &floors)) return Status::Error(r.error());
    if (!r.AtEnd()) return Status::Error("fused front-end state: trailing bytes");
    if (options_.use_barometer && floors.template_level.size() != created.size()) {
      return Status::Error("fused front-end state: template floors do not fit");
    }
    if (camera.size() != created.size() || ws.fingerprints.size() != created.size() ||
        headings.size() != created.size()) {
      return Status::Error("fused front-end state: sensor template counts differ");
    }
    if (options_.online_rssi_offset && calibrated.size() != created.size()) {
      return Status::Error("fused front-end state: RSSI calibration flags do not fit");
    }
    if (before_session > created.size() || !FiniteOrAbsent(session_start) ||
        !AllFinite(estimates) || !AllFinite(offsets)) {
      return Status::Error("fused front-end state: RSSI offset estimates do not fit");
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
    session_start_s_ = session_start;
    templates_before_session_ = before_session;
    offset_estimates_db_ = std::move(estimates);
    offsets_db_ = std::move(offsets);
    calibrated_ = std::move(calibrated);
    if (options_.use_barometer) AdoptFloors(std::move(floors));
    return Status::Ok();
  }

 private:
  enum class Verdict { kNovel, kFamiliarRecent, kMatch };

  // Whether this session's scans are in the first session's units: the first session defines
  // them; a later one once its offset is known. Only such templates give estimates.
  bool InReferenceUnits() const {
    return offsets_db_.empty() ||
           offset_estimates_db_.size() >= static_cast<size_t>(options_.rssi_offset_min_estimates);
  }
  double CurrentOffset() const {
    return offset_estimates_db_.size() >= static_cast<size_t>(options_.rssi_offset_min_estimates)
               ? Median(offset_estimates_db_)
               : 0.0;
  }

  // One estimate from this scan (against the earlier sessions' templates), then the session's
  // offset, once known, removed from the scan.
  void RemoveRssiOffset(Fingerprint* scan) {
    const std::vector<Fingerprint>& stored = wifi_.state().fingerprints;
    double best_spread = std::numeric_limits<double>::infinity(), best_median = 0.0;
    std::vector<double> d;
    for (uint32_t t = 0; t < templates_before_session_ && t < stored.size(); ++t) {
      if (!calibrated_[t]) continue;
      const Fingerprint& f = stored[t];
      d.clear();
      for (size_t a = 0, b = 0; a < scan->ap_ids.size() && b < f.ap_ids.size();) {
        if (scan->ap_ids[a] < f.ap_ids[b]) {
          ++a;
        } else if (f.ap_ids[b] < scan->ap_ids[a]) {
          ++b;
        } else {
          d.push_back(static_cast<double>(scan->rssi_dbm[a++]) - f.rssi_dbm[b++]);
        }
      }
      if (d.size() < static_cast<size_t>(options_.rssi_offset_min_common_aps)) continue;
      double mean = 0.0;
      for (double x : d) mean += x;
      mean /= static_cast<double>(d.size());
      double spread = 0.0;
      for (double x : d) spread += (x - mean) * (x - mean);
      spread /= static_cast<double>(d.size());
      if (spread < best_spread) {  // ties: the older template
        best_spread = spread;
        best_median = Median(d);
      }
    }
    if (std::isfinite(best_spread)) offset_estimates_db_.push_back(best_median);
    const double offset = CurrentOffset();
    if (offset == 0.0) return;
    for (float& rssi : scan->rssi_dbm) rssi = static_cast<float>(rssi - offset);
  }

  // Eqs. 10-11: a sensor's best match counts when it reaches the threshold and is not recent.
  Verdict Judge(int32_t best, double score, double threshold, double time_s) const {
    if (best < 0 || score < threshold) return Verdict::kNovel;
    const int64_t n = static_cast<int64_t>(created_time_s_.size());
    const bool old_enough = OldEnough(n, best, time_s, created_time_s_[best],
                                      options_.recency_templates, options_.recency_s, settled_);
    return old_enough ? Verdict::kMatch : Verdict::kFamiliarRecent;
  }

  // Floors. kNoBarometer: no reading yet in the session (no constraint); kUnknownFloor: on the
  // stairs or before the session's first level (matches nothing with a floor); else a level
  // index of the session's tracker.
  static constexpr int32_t kNoBarometer = -2;
  static constexpr int32_t kUnknownFloor = -1;

  // Everything the floor rule keeps beside the tracker, decoded before it is adopted.
  struct FloorState {
    explicit FloorState(const BarometerOptions& options) : tracker(options) {}
    BarometricFloorTracker tracker;
    uint64_t pressure_readings = 0, floor_changes_before = 0;
    int32_t current_level = kNoBarometer;
    uint32_t session = 0;
    std::optional<double> session_start_s;
    std::vector<std::vector<int32_t>> level_floors;
    std::vector<int32_t> offsets, votes, template_level;
    uint64_t offset_changes = 0;
    std::vector<uint32_t> template_session;
    uint64_t frames_unknown = 0, refused = 0;
  };

  bool DecodeFloors(ByteReader* r, FloorState* f) const {
    size_t n = 0;
    if (!(f->tracker.Decode(r) && r->Pod(&f->pressure_readings) &&
          r->Pod(&f->floor_changes_before) && r->Pod(&f->current_level) && r->Pod(&f->session) &&
          r->Optional(&f->session_start_s) && r->Count(8, &n))) {
      return false;
    }
    f->level_floors.resize(n);
    for (auto& floors : f->level_floors) {
      if (!r->PodVector(&floors)) return false;
    }
    if (!(r->PodVector(&f->offsets) && r->PodVector(&f->votes) && r->Pod(&f->offset_changes) &&
          r->PodVector(&f->template_session) && r->PodVector(&f->template_level) &&
          r->Pod(&f->frames_unknown) && r->Pod(&f->refused))) {
      return false;
    }
    // Every index within what it indexes; the current session the last; the first aligned.
    auto level_ok = [&](uint32_t session, int32_t level) {
      return level == kNoBarometer || level == kUnknownFloor ||
             (level >= 0 && static_cast<size_t>(level) < f->level_floors[session].size());
    };
    if (n == 0 || f->session != n - 1 || f->offsets.size() != n || f->offsets[0] != 0 ||
        f->votes.size() % 3 != 0 || f->template_session.size() != f->template_level.size() ||
        !level_ok(f->session, f->current_level) || !FiniteOrAbsent(f->session_start_s) ||
        (f->tracker.levels() > 0 ? f->level_floors[f->session].size() != f->tracker.levels()
                                 : f->level_floors[f->session].size() > 1)) {
      return r->Fail("floors do not fit together");
    }
    for (size_t t = 0; t < f->template_session.size(); ++t) {
      if (f->template_session[t] >= n || !level_ok(f->template_session[t], f->template_level[t])) {
        return r->Fail("a template's floor names an unknown session or level");
      }
    }
    for (size_t v = 0; v < f->votes.size(); v += 3) {
      const int32_t session = f->votes[v], level = f->votes[v + 1], ours = f->votes[v + 2];
      if (session < 0 || static_cast<uint32_t>(session) >= f->session || level < 0 ||
          !level_ok(static_cast<uint32_t>(session), level) || ours < 0 ||
          !level_ok(f->session, ours)) {
        return r->Fail("a floor vote names no level");
      }
    }
    for (const auto& floors : f->level_floors) {
      for (int32_t floor : floors) {
        if (floor < -100000 || floor > 100000) return r->Fail("a floor number is out of range");
      }
    }
    for (int32_t o : f->offsets) {
      if (o < -100000 || o > 100000) return r->Fail("a floor offset is out of range");
    }
    return true;
  }

  void AdoptFloors(FloorState&& f) {
    tracker_ = std::move(f.tracker);
    pressure_readings_ = f.pressure_readings;
    floor_changes_before_ = f.floor_changes_before;
    current_level_ = f.current_level;
    floor_session_ = f.session;
    floor_session_start_s_ = f.session_start_s;
    session_level_floors_ = std::move(f.level_floors);
    session_offset_ = std::move(f.offsets);
    votes_ = std::move(f.votes);
    floor_offset_changes_ = f.offset_changes;
    template_session_ = std::move(f.template_session);
    template_level_ = std::move(f.template_level);
    frames_floor_unknown_ = f.frames_unknown;
    new_templates_by_floor_rule_ = f.refused;
  }

  void NewFloorSession() {
    floor_changes_before_ += tracker_.floor_changes();
    tracker_ = BarometricFloorTracker(barometer_);
    ++floor_session_;
    session_level_floors_.emplace_back();
    session_offset_.push_back(0);
    votes_.clear();
    current_level_ = kNoBarometer;
  }

  // A level's floor in the map's frame (the first session's first level is floor 0).
  int MapFloor(uint32_t session, int32_t level) const {
    return session_level_floors_[session][level] + session_offset_[session];
  }

  // Whether the barometer lets the current observation match template t (see front_end.h).
  bool FloorAgrees(uint32_t t) const {
    const int32_t level = template_level_[t];
    if (current_level_ == kNoBarometer || level == kNoBarometer) return true;
    if (current_level_ == kUnknownFloor || level == kUnknownFloor) return false;
    const uint32_t session = template_session_[t];
    if (session == floor_session_) return level == current_level_;
    return MapFloor(session, level) == MapFloor(floor_session_, current_level_);
  }

  // A later session's floors start aligned with the first session's (offset 0: walks of one
  // building usually start on one floor) and Wi-Fi revises that. Each scan on a level votes
  // with its best confident match among earlier sessions' templates on a level, whatever their
  // floor, if that match beats the best on any other floor by kFloorVoteRatio: the matched
  // template's floor minus ours. When a value other than 0 leads every other (0 included) by
  // floor_offset_min_votes, the session's offset moves by it.
  static constexpr double kFloorVoteRatio = 1.5;
  void VoteFloorOffset(const Fingerprint& scan) {
    if (current_level_ < 0) return;
    std::vector<uint8_t> candidates(template_level_.size(), 0);
    bool any = false;
    for (size_t t = 0; t < candidates.size(); ++t) {
      candidates[t] = template_level_[t] >= 0 && template_session_[t] != floor_session_;
      any |= candidates[t] != 0;
    }
    if (!any) return;
    const WifiMatch best = wifi_.Best(scan, &candidates);
    if (best.id < 0 || best.weight < wifi_.options().match_threshold) return;
    const int best_floor = MapFloor(template_session_[best.id], template_level_[best.id]);
    for (size_t t = 0; t < candidates.size(); ++t) {
      candidates[t] =
          candidates[t] && MapFloor(template_session_[t], template_level_[t]) != best_floor;
    }
    const WifiMatch other = wifi_.Best(scan, &candidates);
    if (other.id >= 0 && best.weight < kFloorVoteRatio * other.weight) return;  // ambiguous
    votes_.insert(votes_.end(), {static_cast<int32_t>(template_session_[best.id]),
                                 template_level_[best.id], current_level_});
    // This session's votes under today's offsets and level numbers (levels may be renumbered).
    std::vector<std::pair<int, int>> counts = {{0, 0}};  // (their floor minus ours, votes)
    for (size_t v = 0; v < votes_.size(); v += 3) {
      const int value = MapFloor(static_cast<uint32_t>(votes_[v]), votes_[v + 1]) -
                        MapFloor(floor_session_, votes_[v + 2]);
      auto it = std::find_if(counts.begin(), counts.end(),
                             [value](const auto& c) { return c.first == value; });
      if (it == counts.end()) {
        counts.emplace_back(value, 1);
      } else {
        ++it->second;
      }
    }
    std::sort(counts.begin(), counts.end(), [](const auto& a, const auto& b) {
      return a.second != b.second ? a.second > b.second : a.first < b.first;
    });
    const int runner_up = counts.size() > 1 ? counts[1].second : 0;
    if (counts[0].first != 0 && counts[0].second - runner_up >= options_.floor_offset_min_votes) {
      session_offset_[floor_session_] += counts[0].first;
      ++floor_offset_changes_;
    }
  }

  FrameDecision Decide(double time_s, const std::vector<float>* view, const Fingerprint* scan) {
    const uint32_t n = size();
    Verdict camera_verdict = Verdict::kNovel, wifi_verdict = Verdict::kNovel;
    int32_t camera_best = -1, wifi_best = -1;
    // The floor rule, when the barometer has spoken: a flag per template.
    const bool floors = options_.use_barometer && pressure_readings_ > 0;
    std::vector<uint8_t> agrees;
    if (floors) {
      if (current_level_ == kUnknownFloor) ++frames_floor_unknown_;
      if (scan && !scan->empty()) VoteFloorOffset(*scan);
      agrees.resize(n);
      for (uint32_t t = 0; t < n; ++t) agrees[t] = FloorAgrees(t);
    }
    const std::vector<uint8_t>* allowed = floors ? &agrees : nullptr;
    if (view) {
      const KernelCameraMatch best = camera_.Best(*view, allowed);  // eq. 8
      camera_best = best.id;
      camera_verdict = Judge(best.id, best.similarity, camera_.options().match_threshold, time_s);
    }
    if (scan && !scan->empty()) {
      const WifiMatch best = wifi_.Best(*scan, allowed);  // eq. 9
      wifi_best = best.id;
      wifi_verdict = Judge(best.id, best.weight, wifi_.options().match_threshold, time_s);
    }
    if (floors && camera_verdict == Verdict::kNovel && wifi_verdict == Verdict::kNovel) {
      // Would a template on another (or an unknown) floor have matched? Then the rule made this
      // template.
      const bool camera_would =
          view && camera_.Best(*view).similarity >= camera_.options().match_threshold;
      const bool wifi_would =
          scan && !scan->empty() && wifi_.Best(*scan).weight >= wifi_.options().match_threshold;
      new_templates_by_floor_rule_ += camera_would || wifi_would;
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
    if (options_.online_rssi_offset) calibrated_.push_back(InReferenceUnits());
    if (options_.use_barometer) {
      template_session_.push_back(floor_session_);
      template_level_.push_back(current_level_);
    }
    d.view.template_id = n;
    d.view.is_new = true;
    d.source = DecisionSource::kNew;
    return d;
  }

  FusedOptions options_;
  KernelCameraMatcher camera_;
  WifiFingerprintMatcher wifi_;
  std::vector<double> created_time_s_;  // by template
  int64_t settled_ = 0;                 // templates from a saved map (SettleForLocalisation)
  std::vector<std::optional<double>> headings_;  // by template
  Fingerprint newest_scan_;
  std::optional<double> newest_scan_time_s_;
  std::optional<double> heading_rad_;
  // Online RSSI offset: where the current session began, the templates stored before it, this
  // session's estimates and the offsets of the sessions before it.
  std::optional<double> session_start_s_;
  uint32_t templates_before_session_ = 0;
  std::vector<double> offset_estimates_db_;
  std::vector<double> offsets_db_;
  std::vector<uint8_t> calibrated_;  // by template: stored in the reference units (see above)
  // Floors (use_barometer): the current session's tracker and level, every session's level
  // floors and offset to the first session, the current session's votes, each template's
  // session and level (see FloorAgrees).
  BarometerOptions barometer_;
  BarometricFloorTracker tracker_;
  uint64_t pressure_readings_ = 0;
  uint64_t floor_changes_before_ = 0;  // of the sessions before the current one
  int32_t current_level_ = kNoBarometer;
  uint32_t floor_session_ = 0;
  std::optional<double> floor_session_start_s_;
  std::vector<std::vector<int32_t>> session_level_floors_ = {{}};
  std::vector<int32_t> session_offset_ = {0};  // by session: floor offset to the map's frame
  // The current session's votes, three numbers each: template session and level, our level.
  std::vector<int32_t> votes_;
  uint64_t floor_offset_changes_ = 0;
  std::vector<uint32_t> template_session_;
  std::vector<int32_t> template_level_;
  uint64_t frames_floor_unknown_ = 0;
  uint64_t new_templates_by_floor_rule_ = 0;
};

}  // namespace

std::unique_ptr<FrontEnd> MakeFusedFrontEnd(const FusedOptions& options,
                                            const KernelCameraOptions& camera,
                                            const WifiMatcherOptions& wifi,
                                            const BarometerOptions& barometer) {
  return std::make_unique<FusedFrontEnd>(options, camera, wifi, barometer);
}

}  // namespace front_end_internal
}  // namespace ratslam
