// How a saved map encodes the core's state (pose cells, view cells, experiences, records): one
// Describe(archive, object) per type lists its fields in file order; the same function encodes
// (EncodeArchive) and decodes (DecodeArchive). Beside the types, in their namespace, so that the
// archives find them by argument-dependent lookup. The map file as a whole: io/state_schema.h.
// Minimum encoded sizes (the second argument of Objects) let the decoder refuse a count the
// remaining bytes cannot hold before allocating.
#ifndef RATSLAM_RATSLAM_STATE_SCHEMA_H_
#define RATSLAM_RATSLAM_STATE_SCHEMA_H_

#include <cstdint>

#include "ratslam/ratslam.h"
#include "ratslam/records.h"

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

}  // namespace ratslam

#endif  // RATSLAM_RATSLAM_STATE_SCHEMA_H_
