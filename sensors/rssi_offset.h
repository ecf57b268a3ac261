// A phone's RSSI offset to the map, estimated online per session: phones read
// the same place several dB apart, a difference that Wi-Fi kernels and RSSI bins both turn into
// "another place". Shared by the fused and FABMAP front ends, the phone particle filter and
// evaluate (per query session).
//
// Each scan of a later session is compared with the templates of the earlier sessions that are in
// the reference units (the first session's, or a later one's once its offset was known); the
// template whose RSSI differences to the scan spread least (a constant offset costs nothing
// there) gives one estimate, the median difference. Once a session has min_estimates estimates,
// their median is its offset and is removed from its scans, in matching and in the templates it
// stores. No ground truth, no per-phone constant.
#ifndef RATSLAM_SENSORS_RSSI_OFFSET_H_
#define RATSLAM_SENSORS_RSSI_OFFSET_H_

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "common/byte_buffer.h"
#include "sensors/wifi_fingerprint_matcher.h"

namespace ratslam::sensors {

// Readings (AP id, RSSI) as a Fingerprint: sorted by AP, a repeated AP's readings averaged.
Fingerprint FingerprintOf(std::vector<std::pair<uint32_t, double>> readings);

// A scan (objects with `bssid` and `rssi_dbm`, e.g. WifiReading) as a Fingerprint over the AP ids
// in `ids` (a BSSID not in it gets the next id); readings that are not finite are dropped.
template <typename Readings>
Fingerprint InternedFingerprint(const Readings& readings,
                                std::unordered_map<std::string, uint32_t>* ids) {
  std::vector<std::pair<uint32_t, double>> by_id;
  for (const auto& r : readings) {
    if (!std::isfinite(r.rssi_dbm)) continue;
    const auto it = ids->try_emplace(r.bssid, static_cast<uint32_t>(ids->size())).first;
    by_id.emplace_back(it->second, r.rssi_dbm);
  }
  return FingerprintOf(std::move(by_id));
}

class RssiOffsetTracker {
 public:
  RssiOffsetTracker(int min_common_aps, int min_estimates)
      : min_common_aps_(min_common_aps), min_estimates_(min_estimates) {}

  // Called at every frame with its session's start; a new start begins a session whose earlier
  // sessions hold the first `templates` templates.
  void OnSessionStart(double start_s, uint32_t templates);
  // One estimate from `scan` against `stored` (by template id; only the earlier sessions'
  // calibrated templates are read), then the scan in reference units. With `learn` false the
  // scan only gets the offset known so far (a scan not to learn from: the phone standing still).
  void Calibrate(const std::vector<Fingerprint>& stored, Fingerprint* scan, bool learn = true);
  // A template was stored from this session's (calibrated) scan.
  void AddTemplate() { calibrated_.push_back(InReferenceUnits() ? 1 : 0); }

  // The current session's offset (0 until it is known).
  double CurrentOffset() const;
  // Per session so far, the first's (0) included.
  std::vector<double> OffsetsDb() const;

  // The state in the byte layout the fused front end has written since the option existed.
  void Encode(ByteWriter* w) const;
  // Checks sizes against `templates` and that every number is finite; false with r's error set.
  bool Decode(ByteReader* r, size_t templates);

 private:
  bool InReferenceUnits() const;
  // Adds one estimate from `scan`, when a template shares enough APs with it.
  void Estimate(const std::vector<Fingerprint>& stored, const Fingerprint& scan);

  int min_common_aps_;
  int min_estimates_;
  std::optional<double> session_start_s_;
  uint32_t templates_before_session_ = 0;
  std::vector<double> estimates_db_;  // the current session's
  std::vector<double> offsets_db_;    // the earlier sessions'
  std::vector<uint8_t> calibrated_;   // by template: stored in the reference units
};

}  // namespace ratslam::sensors

#endif  // RATSLAM_SENSORS_RSSI_OFFSET_H_
