// FABMAP as the front end: a recognised place re-activates its template, otherwise a new place;
// Wi-Fi learnt from the whole data set or online. See front_end.h.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "common/byte_buffer.h"
#include "fusion/floor_rule.h"
#include "fusion/front_end_internal.h"
#include "sensors/rssi_offset.h"

namespace ratslam::fusion {
namespace front_end_internal {
namespace {

class FabmapFrontEnd : public FrontEnd {
 public:
  FabmapFrontEnd(const FabmapSettings& settings, const FloorOptions& floors,
                 std::shared_ptr<const FabmapResources> resources)
      : settings_(settings),
        resources_(std::move(resources)),
        offset_(settings.front_end.rssi_offset_min_common_aps,
                settings.front_end.rssi_offset_min_estimates),
        floors_(floors) {
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
    if (settings_.front_end.online_rssi_offset) {
      sensors::Fingerprint f = Intern(newest_scan_);
      offset_.Calibrate(reference_, &f);
      const double offset = offset_.CurrentOffset();
      for (WifiReading& r : newest_scan_) r.rssi_dbm -= offset;
    }
    newest_scan_time_s_ = scan.time_s;
    ++scans_seen_;
    if (online() && scans_seen_ >= NextRelearn()) RATSLAM_RETURN_IF_ERROR(Relearn(scans_seen_));
    if (fabmap::UsesVision(mode())) return std::optional<FrameDecision>();  // images are frames
    fabmap::Query q;
    q.wifi = newest_scan_;
    return Decide(scan.time_s, std::move(q));
  }

  void OnCompass(double, double) override {}
  Status OnPressure(double time_s, double pressure_hpa) override {
    return floors_.OnPressure(time_s, pressure_hpa);
  }
  void OnSessionStart(double start_s) override {
    floors_.OnSessionStart(start_s);
    if (settings_.front_end.online_rssi_offset) offset_.OnSessionStart(start_s, size());
    if (session_start_s_ != start_s) {
      session_start_s_ = start_s;
      first_place_of_session_ = size();
      first_scan_of_session_ = scans_.size();
      session_queries_.clear();
    }
  }

  void OnVerifiedRevisit(double current_time_s, double past_time_s) override {
    if (!learn() || !localiser_) return;
    const auto find = [this](double t) -> int64_t {
      const auto it = std::lower_bound(scans_.begin(), scans_.end(), t,
                                       [](const ScanRecord& x, double v) { return x.time_s < v; });
      return it != scans_.end() && it->time_s == t ? it - scans_.begin() : -1;
    };
    const int64_t now = find(current_time_s);
    const int64_t then = find(past_time_s);
    // A scan of this session, not counted yet, showing a place an earlier session made.
    if (now < static_cast<int64_t>(first_scan_of_session_) || then < 0 ||
        then >= static_cast<int64_t>(first_scan_of_session_) || scans_[now].labelled ||
        scans_[then].template_id >= first_place_of_session_) {
      return;
    }
    const fabmap::LocalisationResult r =
        localiser_->Localise(session_queries_[now - first_scan_of_session_]);
    const uint32_t place = scans_[then].template_id;
    if (r.place_probability.size() != places_.size()) return;  // per candidate: no place score
    scans_[now].labelled = true;
    // A place whose posterior underflowed (hundreds of nats below the best) no finite threshold
    // accepts: such a pair says the two scans disagree, not where the threshold belongs.
    const double log_odds = LogOdds(r, place, r.place_probability[place]);
    if (!std::isfinite(log_odds)) return;
    revisit_log_odds_.push_back(log_odds);
    LearnEarlierThreshold();
  }
  FrontEndReport Report() const override {
    FrontEndReport r;
    if (settings_.front_end.online_rssi_offset) r.rssi_offsets_db = offset_.OffsetsDb();
    r.floors = floors_.Report();
    FabmapLearningReport& learning = r.fabmap_learning.emplace();
    learning.wifi_learning = settings_.front_end.wifi_learning;
    learning.wifi_learned_from_scans =
        online() ? learned_from_ : static_cast<uint64_t>(resources_->scans.scans.size());
    learning.wifi_relearnt = online() ? relearnt_ : 1;
    learning.wifi_tree_scans = localiser_ ? localiser_->wifi_tree_scans() : 0;
    if (apart()) learning.earlier_session_log_odds = EarlierThreshold();
    if (learn()) learning.verified_revisits = revisit_log_odds_.size();
    if (calibrate()) {
      learning.verified_revisits = calibration_revisits_;
      learning.calibrated = calibrated_earlier_.has_value();
    }
    return r;
  }
  std::optional<FrontEndCalibration> Learnt() const override {
    if (!learn()) return std::nullopt;
    FrontEndCalibration c;
    c.earlier_session_log_odds = learnt_earlier_;
    c.verified_revisits = revisit_log_odds_.size();
    return c;
  }
  Status Calibrate(const FrontEndCalibration& calibration) override {
    if (!calibrate()) {
      return Status::Error(
          "FABMAP front end: a calibration needs calibrate_earlier_session_log_odds = true");
    }
    if (!places_.empty() || scans_seen_ > 0) {
      return Status::Error("FABMAP front end: a calibration must come before the first frame");
    }
    if (calibration.earlier_session_log_odds &&
        !std::isfinite(*calibration.earlier_session_log_odds)) {
      return Status::Error("FABMAP front end: the calibrated threshold is not finite");
    }
    calibrated_earlier_ = calibration.earlier_session_log_odds;
    calibration_revisits_ = calibration.verified_revisits;
    return Status::Ok();
  }
  std::optional<int> TemplateFloor(uint32_t id) const override { return floors_.TemplateFloor(id); }
  std::optional<double> CompassHeading() const override { return std::nullopt; }
  bool WantsImages() const override { return fabmap::UsesVision(mode()); }
  uint32_t size() const override { return static_cast<uint32_t>(places_.size()); }
  void SettleForLocalisation() override {
    settled_ = size();
    floors_.SettleForLocalisation();
    // Every place of the saved map is of an earlier session than the logs localised in it.
    session_start_s_.reset();
    first_place_of_session_ = size();
    first_scan_of_session_ = scans_.size();
    session_queries_.clear();
  }

  std::string EncodeState() const override {
    ByteWriter w;
    w.Count(places_.size());
    for (size_t i = 0; i < places_.size(); ++i) {
      w.Pod(created_time_s_[i]);
      WriteQuery(&w, places_[i]);
    }
    w.Optional(newest_scan_time_s_);
    WriteReadings(&w, newest_scan_);
    if (online()) {  // whole-data-set states keep the format of earlier releases
      w.Pod(scans_seen_);
      w.Pod(learned_from_);
      w.Pod(relearnt_);
    }
    if (settings_.front_end.online_rssi_offset) offset_.Encode(&w);  // likewise
    // Likewise the session fields and the learning records, only with their options.
    if (apart()) {
      w.Optional(session_start_s_);
      w.Pod(first_place_of_session_);
    }
    if (learn()) {
      w.Count(scans_.size());
      for (const ScanRecord& x : scans_) {
        w.Pod(x.time_s);
        w.Pod(x.template_id);
        w.Bool(x.labelled);
      }
      w.Pod(static_cast<uint64_t>(first_scan_of_session_));
      w.Count(session_queries_.size());
      for (const fabmap::Query& q : session_queries_) WriteQuery(&w, q);
      w.PodVector(revisit_log_odds_);
    }
    if (calibrate()) {
      w.Optional(calibrated_earlier_);
      w.Pod(calibration_revisits_);
    }
    floors_.Encode(&w);
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
    auto query = [&](fabmap::Query* q) {  // what WriteQuery wrote
      bool has_wifi = false;
      std::vector<WifiReading> scan;
      if (!(r.PodVector(&q->visual) && r.Bool(&has_wifi) && readings(&scan))) return false;
      if (has_wifi) q->wifi = std::move(scan);
      return true;
    };
    size_t count = 0;
    std::vector<double> times;
    std::vector<fabmap::Query> places;
    bool ok = r.Count(8 + 8 + 1 + 8, &count);
    for (size_t i = 0; ok && i < count; ++i) {
      double t = 0.0;
      fabmap::Query q;
      ok = r.Pod(&t) && query(&q);
      times.push_back(t);
      places.push_back(std::move(q));
    }
    std::optional<double> newest_time;
    std::vector<WifiReading> newest;
    uint64_t scans_seen = 0, learned_from = 0, relearnt = 0;
    FloorRule floors = floors_;
    sensors::RssiOffsetTracker offset = offset_;
    std::optional<double> session_start;
    uint32_t first_of_session = 0;
    std::vector<ScanRecord> scans;
    uint64_t first_scan = 0;
    std::vector<fabmap::Query> queries;
    std::vector<double> revisits;
    std::optional<double> calibrated;
    uint64_t calibration_revisits = 0;
    auto learning = [&] {
      size_t n = 0;
      if (!r.Count(8 + 4 + 1, &n)) return false;
      scans.resize(n);
      for (ScanRecord& x : scans) {
        if (!(r.Pod(&x.time_s) && r.Pod(&x.template_id) && r.Bool(&x.labelled))) return false;
      }
      if (!(r.Pod(&first_scan) && r.Count(8 + 1 + 8, &n))) return false;
      queries.resize(n);
      for (fabmap::Query& q : queries) {
        if (!query(&q)) return false;
      }
      return r.PodVector(&revisits);
    };
    ok = ok && r.Optional(&newest_time) && readings(&newest) &&
         (!online() || (r.Pod(&scans_seen) && r.Pod(&learned_from) && r.Pod(&relearnt))) &&
         (!settings_.front_end.online_rssi_offset || offset.Decode(&r, count)) &&
         (!apart() || (r.Optional(&session_start) && r.Pod(&first_of_session))) &&
         (!learn() || learning()) &&
         (!calibrate() || (r.Optional(&calibrated) && r.Pod(&calibration_revisits))) &&
         floors.Decode(&r, count) && (r.AtEnd() || r.Fail("trailing bytes"));
    if (!ok) return Status::Error(r.error());
    const bool scans_fit =
        first_scan <= scans.size() && queries.size() == scans.size() - first_scan &&
        std::all_of(scans.begin(), scans.end(),
                    [&](const ScanRecord& x) { return x.template_id < count; }) &&
        std::is_sorted(scans.begin(), scans.end(), [](const ScanRecord& a, const ScanRecord& b) {
          return a.time_s < b.time_s;
        });
    if (!scans_fit) {
      return Status::Error(
          "FABMAP front-end state: the scan records do not fit the places or the session");
    }
    if (first_of_session > count) {
      return Status::Error("FABMAP front-end state: the session's first place " +
                           std::to_string(first_of_session) + " is past its " +
                           std::to_string(count) + " places");
    }
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
    const bool scan_times_ok = std::all_of(
        scans.begin(), scans.end(), [](const ScanRecord& x) { return std::isfinite(x.time_s); });
    const bool revisits_ok = AllFinite(revisits);  // OnVerifiedRevisit keeps finite ones only
    if (!AllFinite(times) || !FiniteOrAbsent(newest_time) || !FiniteOrAbsent(session_start) ||
        !FiniteOrAbsent(calibrated) || !scan_times_ok || !revisits_ok || !readings_ok(newest) ||
        !std::all_of(queries.begin(), queries.end(),
                     [&](const fabmap::Query& q) { return !q.wifi || readings_ok(*q.wifi); }) ||
        !std::all_of(places.begin(), places.end(),
                     [&](const fabmap::Query& q) { return !q.wifi || readings_ok(*q.wifi); })) {
      return Status::Error("FABMAP front-end state: a time or RSSI is not finite");
    }
    Reset();
    places_ = std::move(places);
    created_time_s_ = std::move(times);
    newest_scan_time_s_ = newest_time;
    newest_scan_ = std::move(newest);
    floors_ = std::move(floors);
    offset_ = std::move(offset);
    session_start_s_ = session_start;
    first_place_of_session_ = first_of_session;
    scans_ = std::move(scans);
    first_scan_of_session_ = static_cast<size_t>(first_scan);
    session_queries_ = std::move(queries);
    revisit_log_odds_ = std::move(revisits);
    LearnEarlierThreshold();
    calibrated_earlier_ = calibrated;
    calibration_revisits_ = calibration_revisits;
    for (const fabmap::Query& place : places_) reference_.push_back(Reference(place));
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

  static void WriteReadings(ByteWriter* w, const std::vector<WifiReading>& readings) {
    w->Count(readings.size());
    for (const WifiReading& r : readings) {
      w->String(r.bssid);
      w->Pod(r.rssi_dbm);
    }
  }
  // A place or a scan's query: its visual words and, flagged, its readings.
  static void WriteQuery(ByteWriter* w, const fabmap::Query& q) {
    w->PodVector(q.visual);
    w->Bool(q.wifi.has_value());
    WriteReadings(w, q.wifi ? *q.wifi : std::vector<WifiReading>());
  }

  bool apart() const { return settings_.front_end.earlier_sessions_apart; }
  bool learn() const { return settings_.front_end.learn_earlier_session_log_odds; }
  bool calibrate() const { return settings_.front_end.calibrate_earlier_session_log_odds; }

  // The earlier sessions' threshold: learnt once enough verified revisits are known, or given
  // by a calibration pass; otherwise as configured.
  double EarlierThreshold() const {
    if (learnt_earlier_) return *learnt_earlier_;
    if (calibrated_earlier_) return *calibrated_earlier_;
    return settings_.front_end.earlier_session_log_odds;
  }
  // The highest threshold a place passes (log odds >= t) that at least learn_near_recall of the
  // revisits pass: the revisits' score at rank n - ceil(recall n), lowest first. (The midpoint
  // rule of `evaluate` needs distinct scores: with ties at the bottom it falls to -inf.)
  void LearnEarlierThreshold() {
    learnt_earlier_.reset();
    const size_t n = revisit_log_odds_.size();
    if (n == 0 || n < static_cast<size_t>(settings_.front_end.learn_min_revisits)) return;
    const double want = std::ceil(settings_.front_end.learn_near_recall * n - 1e-9);
    const size_t accepted = std::clamp<size_t>(static_cast<size_t>(want), 1, n);
    std::vector<double> sorted = revisit_log_odds_;
    std::nth_element(sorted.begin(), sorted.begin() + (n - accepted), sorted.end());
    learnt_earlier_ = sorted[n - accepted];
  }

  // learn_earlier_session_log_odds: every Wi-Fi frame decided, in order, with its template.
  void RecordScan(double time_s, uint32_t template_id, const fabmap::Query& q) {
    if (!learn() || !q.wifi || fabmap::UsesVision(mode())) return;
    scans_.push_back({time_s, template_id, false});
    session_queries_.push_back(q);
  }

  void Reset() {
    localiser_ =
        online() ? nullptr : std::make_unique<fabmap::Localiser>(*resources_->empty_localiser);
    session_start_s_.reset();
    first_place_of_session_ = 0;
    scans_.clear();
    first_scan_of_session_ = 0;
    session_queries_.clear();
    revisit_log_odds_.clear();
    learnt_earlier_.reset();
    calibrated_earlier_.reset();
    calibration_revisits_ = 0;
    places_.clear();
    created_time_s_.clear();
    reference_.clear();
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

  // A scan as a fingerprint over this front end's own AP ids (for the RSSI offset estimate):
  // sorted by id, a repeated AP's readings averaged.
  sensors::Fingerprint Intern(const std::vector<WifiReading>& readings) {
    return sensors::InternedFingerprint(readings, &ap_ids_);
  }
  sensors::Fingerprint Reference(const fabmap::Query& place) {
    return settings_.front_end.online_rssi_offset && place.wifi ? Intern(*place.wifi)
                                                                : sensors::Fingerprint();
  }
  void AddPlace(fabmap::Query q, double time_s) {
    floors_.AddTemplate();
    if (settings_.front_end.online_rssi_offset) offset_.AddTemplate();
    reference_.push_back(Reference(q));
    places_.push_back(std::move(q));
    created_time_s_.push_back(time_s);
  }

  // Whether the best place (-1: none) is recognised, by the rule of [fabmap_front_end].
  bool Enough(int64_t best, double probability, double log_odds) const {
    if (best < 0) return false;
    return settings_.front_end.decide_by_log_odds
               ? log_odds >= settings_.front_end.match_log_odds
               : probability >= settings_.front_end.match_probability;
  }

  // A place's log odds against the new place: the best mapped place's, moved by their posteriors'
  // ratio (-inf where either posterior underflowed).
  static double LogOdds(const fabmap::LocalisationResult& r, int64_t place, double probability) {
    if (place >= 0 && place == r.best_mapped_place) return r.best_mapped_log_odds;
    const double mapped = r.best_mapped_probability;
    return place >= 0 && probability > 0.0 && mapped > 0.0
               ? r.best_mapped_log_odds + std::log(probability / mapped)
               : -std::numeric_limits<double>::infinity();
  }

  struct Choice {
    int64_t place = -1;  // -1: the new place
    double probability = 0.0;
    double log_odds = -std::numeric_limits<double>::infinity();
  };

  // earlier_sessions_apart: the best place of the current session against match_log_odds, the
  // best of the earlier sessions against earlier_session_log_odds, among the places `allowed`
  // (every place when empty); of two that pass, the more probable. Needs per-place posteriors.
  Choice ChooseBySession(const fabmap::LocalisationResult& r,
                         const std::vector<uint8_t>& allowed) const {
    Choice earlier, current;
    for (size_t p = 0; p < r.place_probability.size(); ++p) {
      if (!allowed.empty() && !allowed[p]) continue;
      Choice& c = p < first_place_of_session_ ? earlier : current;
      if (c.place < 0 || r.place_probability[p] > c.probability) {
        c.place = static_cast<int64_t>(p);
        c.probability = r.place_probability[p];
      }
    }
    earlier.log_odds = LogOdds(r, earlier.place, earlier.probability);
    current.log_odds = LogOdds(r, current.place, current.probability);
    const bool earlier_ok = earlier.place >= 0 && earlier.log_odds >= EarlierThreshold();
    const bool current_ok =
        current.place >= 0 && current.log_odds >= settings_.front_end.match_log_odds;
    if (earlier_ok && (!current_ok || earlier.probability > current.probability)) return earlier;
    return current_ok ? current : Choice();
  }

  StatusOr<std::optional<FrameDecision>> Decide(double time_s, fabmap::Query q) {
    if (!localiser_) {  // online, before the first model: every frame is a new place
      RecordScan(time_s, static_cast<uint32_t>(places_.size()), q);
      AddPlace(std::move(q), time_s);
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
    const double enough = settings_.front_end.match_probability;
    const bool by_log_odds = settings_.front_end.decide_by_log_odds;
    int64_t best = by_log_odds ? r.best_mapped_place : r.best_place;
    double best_probability = by_log_odds ? r.best_mapped_probability : r.best_probability;
    double best_log_odds = r.best_mapped_log_odds;
    // The posterior is per place except in the sequential modes (per candidate).
    const bool per_place = r.place_probability.size() == places_.size();
    const bool by_session = apart() && per_place && first_place_of_session_ > 0;
    std::vector<uint8_t> agrees;  // the places the barometer allows (empty: no constraint)
    if (floors_.active()) {
      // The floor rule (front_end.h): the most probable place the barometer allows. In the
      // sequential modes a disallowed best place is simply not matched.
      if (per_place) {
        floors_.Vote(
            [&](const std::vector<uint8_t>& mask) {
              std::pair<int64_t, double> top(-1, 0.0);
              for (size_t p = 0; p < mask.size(); ++p) {
                if (mask[p] && (top.first < 0 || r.place_probability[p] > top.second)) {
                  top = {static_cast<int64_t>(p), r.place_probability[p]};
                }
              }
              return top;
            },
            enough);
      }
      agrees = floors_.BeginFrame(static_cast<uint32_t>(n));
    }
    bool recognised = false;
    if (by_session) {
      best = ChooseBySession(r, agrees).place;
      recognised = best >= 0;
      if (!recognised && !agrees.empty() && ChooseBySession(r, {}).place >= 0) {
        floors_.CountRefused();
      }
    } else {
      if (!agrees.empty() && best >= 0 && !agrees[best]) {
        const bool was_enough = Enough(best, best_probability, best_log_odds);
        best = -1;
        best_probability = 0.0;
        for (size_t p = 0; per_place && p < agrees.size(); ++p) {
          if (agrees[p] && (best < 0 || r.place_probability[p] > best_probability)) {
            best = static_cast<int64_t>(p);
            best_probability = r.place_probability[p];
          }
        }
        best_log_odds = LogOdds(r, best, best_probability);
        if (was_enough && !Enough(best, best_probability, best_log_odds)) floors_.CountRefused();
      }
      recognised = Enough(best, best_probability, best_log_odds);
    }
    if (recognised) {
      const bool old_enough =
          OldEnough(n, best, time_s, created_time_s_[best], settings_.front_end.recency_templates,
                    settings_.front_end.recency_s, settled_);
      RecordScan(time_s, static_cast<uint32_t>(best), q);
      d.view.template_id = static_cast<uint32_t>(best);
      d.view.is_new = false;
      d.recent = !old_enough;
      d.view.allow_injection = old_enough;
      return std::optional<FrameDecision>(d);
    }
    RATSLAM_RETURN_IF_ERROR(localiser_->AddPlace(q));
    RecordScan(time_s, static_cast<uint32_t>(n), q);
    AddPlace(std::move(q), time_s);
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
  int64_t settled_ = 0;  // templates from a saved map (SettleForLocalisation)
  // The current session's start and its first place: places before it are of earlier sessions.
  std::optional<double> session_start_s_;
  uint32_t first_place_of_session_ = 0;
  // learn_earlier_session_log_odds: the scans decided (time, template, whether a verified revisit
  // has used it), this session's queries (from first_scan_of_session_ on) to score them again,
  // the verified revisits' log odds for the place their partner scan joined, and the threshold
  // learnt from them (none until learn_min_revisits).
  struct ScanRecord {
    double time_s = 0.0;
    uint32_t template_id = 0;
    bool labelled = false;
  };
  std::vector<ScanRecord> scans_;
  size_t first_scan_of_session_ = 0;
  std::vector<fabmap::Query> session_queries_;
  std::vector<double> revisit_log_odds_;
  std::optional<double> learnt_earlier_;
  // calibrate_earlier_session_log_odds: the threshold a first pass learnt (none: too few
  // revisits there) and the revisits it was learnt from.
  std::optional<double> calibrated_earlier_;
  uint64_t calibration_revisits_ = 0;
  std::vector<WifiReading> newest_scan_;
  std::optional<double> newest_scan_time_s_;
  uint64_t scans_seen_ = 0;    // Wi-Fi scans received
  uint64_t learned_from_ = 0;  // online: scans behind the current model (0: none yet)
  uint64_t relearnt_ = 0;      // online: models built so far
  // [fabmap_front_end] online_rssi_offset (sensors/rssi_offset.h): the estimator, and per place
  // its scan over ap_ids_ (empty without the option or without Wi-Fi).
  sensors::RssiOffsetTracker offset_;
  std::vector<sensors::Fingerprint> reference_;
  std::unordered_map<std::string, uint32_t> ap_ids_;
  FloorRule floors_;  // [barometer] use_barometer: see fusion/floor_rule.h
};

}  // namespace

std::unique_ptr<FrontEnd> MakeFabmapFrontEnd(const FabmapSettings& settings,
                                             const FloorOptions& floors,
                                             std::shared_ptr<const FabmapResources> resources) {
  return std::make_unique<FabmapFrontEnd>(settings, floors, std::move(resources));
}

}  // namespace front_end_internal

StatusOr<std::shared_ptr<const FabmapResources>> PrepareFabmapResources(
    const FrontEndSettings& settings, const dataset::Dataset& dataset,
    std::optional<fabmap::TrainedVisualModel> visual) {
  const FabmapSettings& f = settings.fabmap;
  std::string error;
  if (!f.IsValid(&error)) return Status::Error("FABMAP settings: " + error);
  auto resources = std::make_shared<FabmapResources>();
  const fabmap::FabmapMode mode = f.localiser.localiser.mode;
  if (fabmap::UsesVision(mode)) {
    if (!visual) {
      return Status::Error("FABMAP mode " + fabmap::ToString(mode) +
                           " needs a visual model ([visual_model] file or training_images)");
    }
    resources->visual = std::move(visual);
  }
  fabmap::WifiExploration exploration;
  if (fabmap::UsesWifi(mode)) {
    // Travel at each scan from the odometry (speed held from one row's time to the next's).
    // Without odometry there is no travel (NaN): the Wi-Fi tree is then spaced by time only.
    double travelled = dataset.odometry.empty() ? std::numeric_limits<double>::quiet_NaN() : 0.0;
    double last_time = 0.0;
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

}  // namespace ratslam::fusion
