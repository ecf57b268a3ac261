// The multi-sensor simulator: a robot follows a world's routes session by session and records
// camera views (rendered with OSMesa), Wi-Fi scans, compass headings, wheel odometry and ground
// truth, as a replay data set. Deterministic: the same world and seed give the same bytes.
//
// Motion: along each route segment at constant speed, turning in place at the corners at a
// constant rate; a change of floor between two points at the same place is a lift ride
// (waiting lift_time_s). Sessions follow each other after session_gap_s, the robot starting at
// its route's start. Odometry: speed * (1 + scale error) + noise, turn rate + bias + noise.
// Compass: true heading + noise + local disturbances (Gaussian in distance). Camera: the view
// from (x, y, camera height) along the heading; day is evenly lit, night dim with a lamp on the
// robot; pixel noise, optional horizontal motion blur when turning.
#ifndef RATSLAM_SIM_SIMULATOR_H_
#define RATSLAM_SIM_SIMULATOR_H_

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "common/status.h"
#include "dataset/dataset.h"
#include "render/view_renderer.h"
#include "sim/world.h"

namespace ratslam::sim {

// A true pose of the robot.
struct TruePose {
  double time_s = 0.0;
  double x_m = 0.0, y_m = 0.0, heading_rad = 0.0;
  int floor = 0;
  int session = 0;
  double speed_m_per_s = 0.0, turn_rate_rad_per_s = 0.0;  // over the step ending here
};

// The robot's true motion, sampled every `step_s`.
std::vector<TruePose> TrueTrajectory(const World& world, double step_s);

// Textured triangles of one floor (walls both sides, floor and ceiling), and the people on it
// at `time_s`. `mesh.id` changes only when the geometry does.
render::ViewMesh FloorMesh(const World& world, int floor, double time_s);

// The camera's view at a pose (before noise).
render::ViewCamera CameraAt(const World& world, const TruePose& pose);
render::ViewLighting LightingOf(const World& world, int session);

struct SimulationReport {
  size_t images = 0, scans = 0, odometry_rows = 0, compass_rows = 0;
  double duration_s = 0.0;
};

// Simulates `world` into `dataset`; images go to `image_folder` (PNG, created) when `renderer`
// is given, else the data set has no images. `progress` (optional) gets the fraction done.
Status Simulate(const World& world, uint64_t seed, render::ViewRenderer* renderer,
                const std::string& image_folder, dataset::Dataset* dataset,
                SimulationReport* report, const std::function<void(double)>& progress = nullptr);

}  // namespace ratslam::sim

#endif  // RATSLAM_SIM_SIMULATOR_H_
