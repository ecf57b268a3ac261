// See rssi_offset.h.
#include "sensors/rssi_offset.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/median.h"

namespace ratslam::sensors {

Fingerprint FingerprintOf(std::vector<std::pair<uint32_t, double>> readings) {
  std::sort(readings.begin(), readings.end());
  Fingerprint f;
  for (size_t i = 0; i < readings.size();) {
    size_t j = i;
    double sum = 0.0;
    for (; j < readings.size() && readings[j].first == readings[i].first; ++j) {
      sum += readings[j].second;
    }
    f.ap_ids.push_back(readings[i].first);
    f.rssi_dbm.push_back(static_cast<float>(sum / static_cast<double>(j - i)));
    i = j;
  }
  return f;
}

void RssiOffsetTracker::OnSessionStart(double start_s, uint32_t templates) {
  if (session_start_s_ && *session_start_s_ == start_s) return;
  if (session_start_s_) offsets_db_.push_back(CurrentOffset());
  session_start_s_ = start_s;
  templates_before_session_ = templates;
  estimates_db_.clear();
}

bool RssiOffsetTracker::InReferenceUnits() const {
  return offsets_db_.empty() || estimates_db_.size() >= static_cast<size_t>(min_estimates_);
}

double RssiOffsetTracker::CurrentOffset() const {
  return estimates_db_.size() >= static_cast<size_t>(min_estimates_) ? Median(estimates_db_) : 0.0;
}

std::vector<double> RssiOffsetTracker::OffsetsDb() const {
  std::vector<double> all = offsets_db_;
  all.push_back(CurrentOffset());
  return all;
}

void RssiOffsetTracker::Calibrate(const std::vector<Fingerprint>& stored, Fingerprint* scan,
                                  bool learn) {
  if (learn) Estimate(stored, *scan);
  const double offset = CurrentOffset();
  if (offset == 0.0) return;
  for (float& rssi : scan->rssi_dbm) rssi = static_cast<float>(rssi - offset);
}

void RssiOffsetTracker::Estimate(const std::vector<Fingerprint>& stored, const Fingerprint& scan) {
  double best_spread = std::numeric_limits<double>::infinity(), best_median = 0.0;
  std::vector<double> d;
  for (uint32_t t = 0; t < templates_before_session_ && t < stored.size(); ++t) {
    if (t >= calibrated_.size() || !calibrated_[t]) continue;
    const Fingerprint& f = stored[t];
    d.clear();
    for (size_t a = 0, b = 0; a < scan.ap_ids.size() && b < f.ap_ids.size();) {
      if (scan.ap_ids[a] < f.ap_ids[b]) {
        ++a;
      } else if (f.ap_ids[b] < scan.ap_ids[a]) {
        ++b;
      } else {
        d.push_back(static_cast<double>(scan.rssi_dbm[a++]) - f.rssi_dbm[b++]);
      }
    }
    if (d.size() < static_cast<size_t>(min_common_aps_)) continue;
    // Sums in value order: the estimate does not depend on how APs happen to be numbered (a
    // resumed FABMAP front end numbers them afresh).
    std::sort(d.begin(), d.end());
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
  if (std::isfinite(best_spread)) estimates_db_.push_back(best_median);
}

void RssiOffsetTracker::Encode(ByteWriter* w) const {
  w->Optional(session_start_s_);
  w->Pod(templates_before_session_);
  w->PodVector(estimates_db_);
  w->PodVector(offsets_db_);
  w->PodVector(calibrated_);
}

bool RssiOffsetTracker::Decode(ByteReader* r, size_t templates) {
  std::optional<double> session_start;
  uint32_t before_session = 0;
  std::vector<double> estimates, offsets;
  std::vector<uint8_t> calibrated;
  if (!(r->Optional(&session_start) && r->Pod(&before_session) && r->PodVector(&estimates) &&
        r->PodVector(&offsets) && r->PodVector(&calibrated))) {
    return false;
  }
  if (calibrated.size() != templates) {
    return r->Fail("RSSI calibration flags do not fit the templates");
  }
  auto finite = [](const std::vector<double>& v) {
    for (double x : v) {
      if (!std::isfinite(x)) return false;
    }
    return true;
  };
  if (before_session > templates || (session_start && !std::isfinite(*session_start)) ||
      !finite(estimates) || !finite(offsets)) {
    return r->Fail("RSSI offset estimates do not fit");
  }
  session_start_s_ = session_start;
  templates_before_session_ = before_session;
  estimates_db_ = std::move(estimates);
  offsets_db_ = std::move(offsets);
  calibrated_ = std::move(calibrated);
  return true;
}

}  // namespace ratslam::sensors
