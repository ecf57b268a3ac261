// A small built-in data set so that the demo runs with no download: a robot drives a rounded
// rectangle several times through a field of textured pillars. The camera image is ray-cast
// from the true pose (so views repeat where the place repeats), the wheel odometry has a scale
// error, a turn-rate bias and noise, and the true pose is the ground truth. Deterministic from
// the seed on every platform.
#ifndef RATSLAM_DATASET_SYNTHETIC_DATASET_H_
#define RATSLAM_DATASET_SYNTHETIC_DATASET_H_

#include <cstdint>
#include <string>
#include <vector>

#include "common/status.h"
#include "dataset/dataset.h"

namespace ratslam::dataset {

struct SyntheticOptions {
  uint64_t seed = 1;                // the world (pillars), and the noise unless noise_seed is set
  uint64_t noise_seed = 0;          // sensor noise; 0: derived from seed. Another noise seed is
                                    // another session in the same world and frame
  double start_m = 0.0;             // distance along the loop where the robot starts
  int laps = 3;                     // times round the loop
  double loop_length_m = 40.0;      // outer size of the rounded rectangle along x
  double loop_width_m = 24.0;       // outer size along y
  double corner_radius_m = 4.0;     // radius of the rounded corners
  double speed_m_per_s = 1.0;       // true forward speed
  double rate_hz = 10.0;            // camera and odometry rate
  double lap_offset_m = 0.15;       // lateral offset of the path, alternating per lap
  int pillars = 160;                // landmarks around the route
  double pillar_clearance_m = 1.5;  // no pillar closer than this to the path
  double field_margin_m = 12.0;     // pillars lie within this distance outside the loop
  int image_width_px = 120;         // camera image size
  int image_height_px = 40;
  double field_of_view_rad = 1.8;           // horizontal field of view (about 103 degrees)
  double pixel_noise_grey = 3.0;            // standard deviation of image noise, grey levels
  double odometry_scale = 1.03;             // measured / true forward speed
  double turn_rate_bias_rad_per_s = 0.004;  // added to every measured turn rate
  double speed_noise_m_per_s = 0.02;        // standard deviation per sample
  double turn_rate_noise_rad_per_s = 0.01;  // standard deviation per sample

  bool IsValid(std::string* error) const;
};

// Generates the data set and writes it, with its PNG images, into `folder`.
StatusOr<Dataset> WriteSyntheticDataset(const SyntheticOptions& options, const std::string& folder);

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_SYNTHETIC_DATASET_H_
