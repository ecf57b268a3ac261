// How a saved map encodes the Wi-Fi sequence loop closer's state: one Describe(archive, object) per
// type lists its fields in file order; the same function encodes (EncodeArchive) and decodes
// (DecodeArchive). Beside the types, in their namespace, so that the archives find them by
// argument-dependent lookup. The map file as a whole: io/state_schema.h. Minimum encoded sizes (the
// second argument of Objects) let the decoder refuse a count the remaining bytes cannot hold before
// allocating.
#ifndef RATSLAM_FUSION_WIFI_SEQUENCE_STATE_SCHEMA_H_
#define RATSLAM_FUSION_WIFI_SEQUENCE_STATE_SCHEMA_H_

#include "fusion/wifi_sequence/wifi_sequence.h"

namespace ratslam::wifi_sequence {

template <typename A>
bool Describe(A& a, PoseSignal& s) {
  return a(s.aps) && a(s.quality) &&
         a.Check(s.aps.size() == s.quality.size(), "Wi-Fi sequence signal sizes differ");
}

template <typename A>
bool Describe(A& a, SequencePose& p) {
  return a(p.time_s) && a(p.travel_m) && a.Object(p.odometry) && a(p.anchor) &&
         a.Object(p.anchor_offset) && a(p.compass_heading_rad);
}

template <typename A>
bool Describe(A& a, SequenceCorrespondence& c) {
  return a(c.current_pose) && a(c.past_pose) && a(c.similarity) && a(c.inlier) && a(c.residual_m);
}

template <typename A>
bool Describe(A& a, SequenceLoop& l) {
  return a(l.id) && a(l.time_s) && a(l.current_sequence) && a(l.past_sequence) &&
         a.Objects(l.correspondences, 25) && a.Object(l.transform) && a(l.dp_cost) &&
         a(l.inliers) && a(l.reversed) && a(l.accepted) && a(l.outcome);
}

template <typename A>
bool Describe(A& a, WifiSequenceLoopCloser::State& s) {
  return a.Objects(s.bssids, 8) && a.Objects(s.poses, 81) && a.Objects(s.signals, 16) &&
         a(s.open_sequence) && a(s.open_continues) && a(s.open_start_radius_m) &&
         a(s.open_end_radius_m) && a.Objects(s.loops, 82);
}

}  // namespace ratslam::wifi_sequence

#endif  // RATSLAM_FUSION_WIFI_SEQUENCE_STATE_SCHEMA_H_
