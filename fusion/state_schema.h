// How a saved map encodes the replay pipeline's state: one Describe(archive, object) per type lists
// its fields in file order; the same function encodes (EncodeArchive) and decodes (DecodeArchive).
// Beside the types, in their namespace, so that the archives find them by argument-dependent
// lookup. The map file as a whole: io/state_schema.h. Minimum encoded sizes (the second argument
// of Objects) let the decoder refuse a count the remaining bytes cannot hold before allocating.
#ifndef RATSLAM_FUSION_STATE_SCHEMA_H_
#define RATSLAM_FUSION_STATE_SCHEMA_H_

#include "fusion/replay_pipeline.h"
#include "fusion/wifi_sequence/state_schema.h"
#include "ratslam/state_schema.h"

namespace ratslam::fusion {

template <typename A>
bool Describe(A& a, ReplayPipeline::State& s) {
  return a.Object(s.ratslam) && a(s.front_end) && a(s.next_event) && a(s.events_total) &&
         a(s.last_odometry_time_s) && a(s.have_odometry) && a(s.odometry_x_m) &&
         a(s.odometry_y_m) && a(s.odometry_theta_rad) && a.Objects(s.trajectory, 64) &&
         a.Objects(s.frames, 23) && a(s.wifi_scans_seen) && a(s.compass_readings_seen) &&
         a(s.images_skipped) &&
         (a.version() < 6 ||
          (a.Object(s.wifi_sequence) && a(s.travel_m) && a(s.wifi_sequence_flushed)));
}

}  // namespace ratslam::fusion

#endif  // RATSLAM_FUSION_STATE_SCHEMA_H_
