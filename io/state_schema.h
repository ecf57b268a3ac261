// The map file's schema: one Describe(archive, object) per saved type lists its fields in file
// order. The same function encodes (EncodeArchive) and decodes (DecodeArchive), and a test counts
// each struct's members against its description, so a member added to a state struct but not
// here fails the build's tests instead of being silently dropped from saved maps.
//
// Minimum encoded sizes (the second argument of Objects) let the decoder refuse a count that the
// remaining bytes cannot hold before it allocates anything.
#ifndef RATSLAM_IO_STATE_SCHEMA_H_
#define RATSLAM_IO_STATE_SCHEMA_H_

#include <cstdint>

#include "common/byte_buffer.h"
#include "fusion/replay_pipeline.h"
#include "io/map_file.h"
#include "ratslam/ratslam.h"

namespace ratslam {

template <typename A>
bool Describe(A& a, PoseCellPosition& p) {
  return a(p.x) && a(p.y) && a(p.theta);
}

template <typename A>
bool Describe(A& a, LocalOffset& o) {
  return a(o.forward_m) && a(o.left_m) && a(o.facing_rad);
}

template <typename A>
bool Describe(A& a, PoseCellNetwork::State& s) {
  return a(s.active_indices) && a(s.active_values) && a(s.residual_x_cells) &&
         a(s.residual_y_cells) && a(s.residual_theta_cells);
}

template <typename A>
bool Describe(A& a, ViewTemplate& t) {
  return a(t.id) && a.Object(t.pose_cells) && a(t.created_time_s) && a(t.decay) &&
         a(t.decay_frame) && a(t.match_count) && a(t.experience_ids) &&
         (a.version() < 5 || a(t.decay_time_s));
}

template <typename A>
bool Describe(A& a, LocalViewCells::State& s) {
  return a(s.frame) && a.Objects(s.templates, 64);
}

template <typename A>
bool Describe(A& a, Experience& e) {
  return a(e.id) && a(e.x_m) && a(e.y_m) && a(e.theta_rad) && a(e.template_id) &&
         a.Object(e.pose_cells) && a(e.time_s) && a(e.compass_heading_rad) && a(e.link_ids);
}

template <typename A>
bool Describe(A& a, Link& l) {
  return a(l.id) && a(l.from) && a(l.to) && a(l.distance_m) && a(l.heading_rad) &&
         a(l.facing_rad) && a(l.duration_s) && a(l.loop_closure) &&
         (a.version() < 6 || a(l.wifi_sequence));
}

template <typename A>
bool Describe(A& a, ExperienceMap::State& s) {
  return a.Objects(s.experiences, 81) && a.Objects(s.links, 45) && a(s.current) &&
         a.Object(s.offset) && a(s.offset_start_time_s) &&
         (a.version() < 4 || a(s.relaxation_pending_links));
}

template <typename A>
bool Describe(A& a, Ratslam::Counters& c) {
  return a(c.odometry_steps) && a(c.view_frames) && a(c.injections) && a(c.loop_closures) &&
         a(c.refused_ambiguous);
}

template <typename A>
bool Describe(A& a, Ratslam::State& s) {
  return a.Object(s.pose_cells) && a.Object(s.local_view) && a.Object(s.experience_map) &&
         a(s.current_template) && a.Object(s.counters) && a(s.compass_heading_rad);
}

template <typename A>
bool Describe(A& a, TrajectoryRecord& t) {
  return a(t.time_s) && a(t.experience_id) && a.Object(t.offset) && a(t.odometry_x_m) &&
         a(t.odometry_y_m) && a(t.odometry_theta_rad);
}

template <typename A>
bool Describe(A& a, FrameRecord& f) {
  return a(f.time_s) && a(f.template_id) && a(f.is_new) && a(f.experience_id) && a(f.source) &&
         a.Check(static_cast<uint8_t>(f.source) <= 2, "invalid decision source") && a(f.recent);
}

template <typename A>
bool Describe(A& a, Pose2& p) {
  return a(p.x_m) && a(p.y_m) && a(p.theta_rad);
}

template <typename A>
bool Describe(A& a, std::string& s) {
  return a(s);
}

template <typename A>
bool Describe(A& a, wifi_sequence::PoseSignal& s) {
  return a(s.aps) && a(s.quality) &&
         a.Check(s.aps.size() == s.quality.size(), "Wi-Fi sequence signal sizes differ");
}

template <typename A>
bool Describe(A& a, wifi_sequence::SequencePose& p) {
  return a(p.time_s) && a(p.travel_m) && a.Object(p.odometry) && a(p.anchor) &&
         a.Object(p.anchor_offset) && a(p.compass_heading_rad);
}

template <typename A>
bool Describe(A& a, wifi_sequence::SequenceCorrespondence& c) {
  return a(c.current_pose) && a(c.past_pose) && a(c.similarity) && a(c.inlier) && a(c.residual_m);
}

template <typename A>
bool Describe(A& a, wifi_sequence::SequenceLoop& l) {
  return a(l.id) && a(l.time_s) && a(l.current_sequence) && a(l.past_sequence) &&
         a.Objects(l.correspondences, 25) && a.Object(l.transform) && a(l.dp_cost) &&
         a(l.inliers) && a(l.reversed) && a(l.accepted) && a(l.outcome);
}

template <typename A>
bool Describe(A& a, wifi_sequence::WifiSequenceLoopCloser::State& s) {
  return a.Objects(s.bssids, 8) && a.Objects(s.poses, 81) && a.Objects(s.signals, 16) &&
         a(s.open_sequence) && a(s.open_continues) && a(s.open_start_radius_m) &&
         a(s.open_end_radius_m) && a.Objects(s.loops, 82);
}

template <typename A>
bool Describe(A& a, fusion::ReplayPipeline::State& s) {
  return a.Object(s.ratslam) && a(s.front_end) && a(s.next_event) && a(s.events_total) &&
         a(s.last_odometry_time_s) && a(s.have_odometry) && a(s.odometry_x_m) &&
         a(s.odometry_y_m) && a(s.odometry_theta_rad) && a.Objects(s.trajectory, 64) &&
         a.Objects(s.frames, 23) && a(s.wifi_scans_seen) && a(s.compass_readings_seen) &&
         a(s.images_skipped) &&
         (a.version() < 6 ||
          (a.Object(s.wifi_sequence) && a(s.travel_m) && a(s.wifi_sequence_flushed)));
}

// The header after the magic bytes and version: which options and data set made the map. The
// resolved configuration was added in format 3.
template <typename A>
bool Describe(A& a, MapFile& m) {
  return a(m.config_fingerprint) && a(m.dataset_name) && (a.version() < 3 || a(m.config)) &&
         a.Object(m.state);
}

}  // namespace ratslam

#endif  // RATSLAM_IO_STATE_SCHEMA_H_
