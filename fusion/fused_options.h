// Options of the fused front end ([front_end] kind = "fused") and of the floors the fused and
// FABMAP front ends take from a barometer.
//
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
//
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
#ifndef RATSLAM_FUSION_FUSED_OPTIONS_H_
#define RATSLAM_FUSION_FUSED_OPTIONS_H_

#include <cstdint>
#include <string>
#include <vector>

#include "common/schema.h"
#include "sensors/barometer.h"

namespace ratslam::fusion {

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
  // Estimate the offset only from scans taken while walking (odometry moved just before the
  // scan: FrontEnd::OnWalking), not while the phone stands or is waved in a calibration gesture
  // (the PDR counts no steps then), when the body's shadow and the gesture bias the RSSI.
  bool rssi_offset_walking_only = false;
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
    v("rssi_offset_walking_only", rssi_offset_walking_only,
      "estimate the offset only from scans taken while walking (odometry moved within the PDR's "
      "max_step_interval_s before the scan), not while standing or making the calibration "
      "gesture",
      schema::Any());
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
  sensors::BarometerOptions tracker;

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

}  // namespace ratslam::fusion

#endif  // RATSLAM_FUSION_FUSED_OPTIONS_H_
