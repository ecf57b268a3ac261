// Worlds for the multi-sensor simulator: floors of walls with materials and textures, access
// points, magnetic disturbances, people, routes and sessions, plus every sensor's settings.
// Described in TOML (see configs/README.md, "Simulator worlds"); unknown keys, wrong types and
// bad values are errors naming the file and line. Five worlds are built in.
#ifndef RATSLAM_SIM_WORLD_H_
#define RATSLAM_SIM_WORLD_H_

#include <map>
#include <string>
#include <vector>

#include "common/status.h"

namespace ratslam::sim {

struct Point2 {
  double x_m = 0.0, y_m = 0.0;
};

struct Wall {
  int floor = 0;
  Point2 from, to;
  std::string material = "drywall";  // attenuation from World::materials_db
  std::string texture = "plaster";   // kind, optionally ":variant" (see textures.h)
  double height_m = 3.0;
};

struct AccessPoint {
  std::string name;  // becomes the BSSID
  Point2 position;
  int floor = 0;
  double tx_power_dbm = 20.0;
  int channel = 6;                     // 1-13: 2.4 GHz; 36 and up: 5 GHz
  std::vector<int> off_in_sessions;    // switched off in these sessions (environment change)
  std::vector<int> moved_in_sessions;  // at `moved_to` in these sessions
  Point2 moved_to;
};

struct Disturbance {  // a local magnetic disturbance (steel, machinery)
  Point2 position;
  int floor = 0;
  double radius_m = 2.0;       // Gaussian radius of the effect
  double strength_deg = 30.0;  // heading error at the centre
};

struct Person {  // a moving obstacle walking back and forth between two points
  int floor = 0;
  Point2 from, to;
  double speed_m_per_s = 0.8;
  std::string texture = "person";
};

struct RoutePoint {
  Point2 position;
  int floor = 0;
};

struct Route {
  std::string name;
  std::vector<RoutePoint> points;
  bool closed = false;  // the last point connects back to the first
};

struct Session {
  std::string route;
  double laps = 1.0;             // times along the route (fractions allowed; closed routes)
  bool reverse = false;          // traverse the route backwards
  std::string lighting = "day";  // day or night
};

struct CameraSettings {
  int width_px = 128, height_px = 96;  // enough for ORB features (FABMAP), cheap to render
  double horizontal_fov_deg = 90.0;
  double height_m = 1.2;
  double pitch_deg = 0.0;
  double rate_hz = 4.0;
  double noise_sigma = 2.0;  // grey levels (0..255)
  bool motion_blur = false;  // horizontal blur proportional to the turn rate
};

struct WifiSettings {
  double path_loss_exponent = 3.0;       // n of the log-distance model
  double reference_distance_m = 1.0;     // d0; free-space loss up to it
  double floor_attenuation_db = 15.0;    // per floor between AP and receiver
  double shadowing_sigma_db = 4.0;       // log-normal shadowing, spatially correlated
  double shadowing_correlation_m = 3.0;  // grid spacing of the shadowing field
  double fading_sigma_db = 2.0;          // independent per scan and AP
  double sensitivity_dbm = -90.0;        // weaker readings are not reported
  double scan_period_s = 2.0;
  double miss_probability = 0.05;  // an AP above sensitivity missing from a scan
};

struct CompassSettings {
  double rate_hz = 10.0;
  double noise_sigma_deg = 2.0;
};

struct OdometrySettings {
  double rate_hz = 10.0;
  double speed_scale_error = 0.03;     // systematic: reported = true * (1 + error)
  double turn_bias_rad_per_s = 0.002;  // systematic turn-rate bias
  double speed_noise_m_per_s = 0.02;
  double turn_noise_rad_per_s = 0.01;
};

struct MotionSettings {
  double speed_m_per_s = 1.0;
  double turn_rate_rad_per_s = 1.0;  // turning in place at route corners
  double lift_time_s = 10.0;         // waiting in a lift between floors
  double session_gap_s = 5.0;        // time between sessions
};

struct World {
  std::string name;
  std::map<std::string, double> materials_db = {
      {"drywall", 4.0}, {"concrete", 12.0}, {"glass", 2.0}, {"wood", 3.0}, {"metal", 20.0}};
  std::vector<Wall> walls;
  std::vector<AccessPoint> access_points;
  std::vector<Disturbance> disturbances;
  std::vector<Person> people;
  std::vector<Route> routes;
  std::vector<Session> sessions;
  CameraSettings camera;
  WifiSettings wifi;
  CompassSettings compass;
  OdometrySettings odometry;
  MotionSettings motion;

  // Every reference resolves (routes, materials, textures) and every value is in range.
  Status Validate() const;
};

// Parses a world file's text; `source` names it in messages ("file:line: ...").
StatusOr<World> ParseWorld(const std::string& text, const std::string& source);
StatusOr<World> LoadWorldFile(const std::string& path);
// The world as TOML that ParseWorld reads back to the same world.
std::string PrintWorld(const World& world);

// Built-in worlds: office, circular, day_night, aliased_floors, apartment.
std::vector<std::string> BuiltInWorldNames();
StatusOr<World> BuiltInWorld(const std::string& name);

}  // namespace ratslam::sim

#endif  // RATSLAM_SIM_WORLD_H_
