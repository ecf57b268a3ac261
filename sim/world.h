// Worlds for the multi-sensor simulator: floors of walls with materials and textures, access
// points, magnetic disturbances, people, routes and sessions, plus every sensor's settings.
// Described in TOML (see configs/README.md, "Simulator worlds"); unknown keys, wrong types and
// bad values are errors naming the file and line. Five worlds are built in.
#ifndef RATSLAM_SIM_WORLD_H_
#define RATSLAM_SIM_WORLD_H_

#include <map>
#include <string>
#include <vector>

#include "common/schema.h"
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

  template <typename V>
  void VisitFields(V&& v) {
    v("floor", floor, "floor the wall stands on", schema::Unit("").Within(-1000, 1000));
    v("from", from, "one end [x, y]", schema::Unit("m"));
    v("to", to, "the other end [x, y]", schema::Unit("m"));
    v("material", material, "name of a [materials] entry", schema::Any().NotEmpty());
    v("texture", texture, "texture kind, optionally \":variant\"", schema::Any().NotEmpty());
    v("height_m", height_m, "wall height", schema::Unit("m").Positive());
  }
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

  template <typename V>
  void VisitFields(V&& v) {
    v("name", name, "unique name; becomes the BSSID", schema::Any().NotEmpty());
    v("position", position, "[x, y]", schema::Unit("m"));
    v("floor", floor, "floor of the access point", schema::Unit("").Within(-1000, 1000));
    v("tx_power_dbm", tx_power_dbm, "transmit power", schema::Unit("dBm").Within(-50, 50));
    v("channel", channel, "1-14 (2.4 GHz) or 32-177 (5 GHz)", schema::Unit("").Within(1, 177));
    v("off_in_sessions", off_in_sessions, "sessions in which it is switched off",
      schema::Unit("").NonNegative());
    v("moved_in_sessions", moved_in_sessions, "sessions in which it stands at moved_to",
      schema::Unit("").NonNegative());
    v("moved_to", moved_to, "[x, y] in those sessions", schema::Unit("m"));
  }
};

struct Disturbance {  // a local magnetic disturbance (steel, machinery)
  Point2 position;
  int floor = 0;
  double radius_m = 2.0;       // Gaussian radius of the effect
  double strength_deg = 30.0;  // heading error at the centre

  template <typename V>
  void VisitFields(V&& v) {
    v("position", position, "centre [x, y]", schema::Unit("m"));
    v("floor", floor, "floor of the disturbance", schema::Unit("").Within(-1000, 1000));
    v("radius_m", radius_m, "Gaussian radius of the effect", schema::Unit("m").Positive());
    v("strength_deg", strength_deg, "heading error at the centre", schema::Unit("deg"));
  }
};

struct Person {  // a moving obstacle walking back and forth between two points
  int floor = 0;
  Point2 from, to;
  double speed_m_per_s = 0.8;
  std::string texture = "person";

  template <typename V>
  void VisitFields(V&& v) {
    v("floor", floor, "floor the person walks on", schema::Unit("").Within(-1000, 1000));
    v("from", from, "one end of the walk [x, y]", schema::Unit("m"));
    v("to", to, "the other end [x, y]", schema::Unit("m"));
    v("speed_m_per_s", speed_m_per_s, "walking speed", schema::Unit("m/s").Positive());
    v("texture", texture, "texture kind", schema::Any().NotEmpty());
  }
};

struct RoutePoint {
  Point2 position;
  int floor = 0;
};

struct Route {
  std::string name;
  std::vector<RoutePoint> points;
  bool closed = false;  // the last point connects back to the first

  template <typename V>
  void VisitFields(V&& v) {
    v("name", name, "name sessions refer to", schema::Any());
    v("closed", closed, "the last point connects back to the first", schema::Any());
    v("points", points, "[x, y, floor] corners in order", schema::Unit("m"));
  }
};

struct Session {
  std::string route;
  double laps = 1.0;             // times along the route (fractions allowed; closed routes)
  bool reverse = false;          // traverse the route backwards
  std::string lighting = "day";  // day or night

  template <typename V>
  void VisitFields(V&& v) {
    v("route", route, "name of the route walked", schema::Any());
    v("laps", laps, "times along the route", schema::Unit("laps").Above(0).AtMost(1000));
    v("reverse", reverse, "traverse the route backwards", schema::Any());
    v("lighting", lighting, "day or night", schema::Any());
  }
};

struct CameraSettings {
  int width_px = 128, height_px = 96;  // enough for ORB features (FABMAP), cheap to render
  double horizontal_fov_deg = 90.0;
  double height_m = 1.2;
  double pitch_deg = 0.0;
  double rate_hz = 4.0;
  double noise_sigma = 2.0;  // grey levels (0..255)
  bool motion_blur = false;  // horizontal blur proportional to the turn rate

  template <typename V>
  void VisitFields(V&& v) {
    v("width_px", width_px, "image width", schema::Unit("px").Within(8, 1024));
    v("height_px", height_px, "image height", schema::Unit("px").Within(8, 1024));
    v("horizontal_fov_deg", horizontal_fov_deg, "horizontal field of view",
      schema::Unit("deg").Above(10).Below(170));
    v("height_m", height_m, "camera height above the floor", schema::Unit("m").Positive());
    v("pitch_deg", pitch_deg, "upward tilt", schema::Unit("deg").Within(-90, 90));
    v("rate_hz", rate_hz, "frames per second", schema::Unit("Hz").Positive().AtMost(100));
    v("noise_sigma", noise_sigma, "pixel noise in grey levels (0..255)",
      schema::Unit("").NonNegative());
    v("motion_blur", motion_blur, "horizontal blur proportional to the turn rate", schema::Any());
  }
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

  template <typename V>
  void VisitFields(V&& v) {
    v("path_loss_exponent", path_loss_exponent, "n of the log-distance model",
      schema::Unit("").Positive());
    v("reference_distance_m", reference_distance_m, "d0; free-space loss up to it",
      schema::Unit("m").Positive());
    v("floor_attenuation_db", floor_attenuation_db, "per floor between AP and receiver",
      schema::Unit("dB").NonNegative());
    v("shadowing_sigma_db", shadowing_sigma_db, "log-normal shadowing, spatially correlated",
      schema::Unit("dB").NonNegative());
    // Below a centimetre the shadowing grid index of a point 100 km away overflows an integer.
    v("shadowing_correlation_m", shadowing_correlation_m, "grid spacing of the shadowing field",
      schema::Unit("m").AtLeast(0.01));
    v("fading_sigma_db", fading_sigma_db, "independent per scan and AP",
      schema::Unit("dB").NonNegative());
    v("sensitivity_dbm", sensitivity_dbm, "weaker readings are not reported",
      schema::Unit("dBm").Within(-200, 0));
    v("scan_period_s", scan_period_s, "time between scans", schema::Unit("s").AtLeast(0.01));
    v("miss_probability", miss_probability, "an AP above sensitivity missing from a scan",
      schema::Unit("").AtLeast(0).Below(1));
  }
};

struct CompassSettings {
  double rate_hz = 10.0;
  double noise_sigma_deg = 2.0;

  template <typename V>
  void VisitFields(V&& v) {
    v("rate_hz", rate_hz, "readings per second", schema::Unit("Hz").Positive().AtMost(1000));
    v("noise_sigma_deg", noise_sigma_deg, "heading noise", schema::Unit("deg").NonNegative());
  }
};

struct OdometrySettings {
  double rate_hz = 10.0;
  double speed_scale_error = 0.03;     // systematic: reported = true * (1 + error)
  double turn_bias_rad_per_s = 0.002;  // systematic turn-rate bias
  double speed_noise_m_per_s = 0.02;
  double turn_noise_rad_per_s = 0.01;

  template <typename V>
  void VisitFields(V&& v) {
    v("rate_hz", rate_hz, "readings per second", schema::Unit("Hz").Positive().AtMost(1000));
    v("speed_scale_error", speed_scale_error, "systematic: reported = true * (1 + error)",
      schema::Unit("").Above(-1));
    v("turn_bias_rad_per_s", turn_bias_rad_per_s, "systematic turn-rate bias",
      schema::Unit("rad/s"));
    v("speed_noise_m_per_s", speed_noise_m_per_s, "speed noise", schema::Unit("m/s").NonNegative());
    v("turn_noise_rad_per_s", turn_noise_rad_per_s, "turn-rate noise",
      schema::Unit("rad/s").NonNegative());
  }
};

struct MotionSettings {
  double speed_m_per_s = 1.0;
  double turn_rate_rad_per_s = 1.0;  // turning in place at route corners
  double lift_time_s = 10.0;         // waiting in a lift between floors
  double session_gap_s = 5.0;        // time between sessions

  template <typename V>
  void VisitFields(V&& v) {
    v("speed_m_per_s", speed_m_per_s, "walking or driving speed",
      schema::Unit("m/s").AtLeast(0.01));
    v("turn_rate_rad_per_s", turn_rate_rad_per_s, "turning in place at route corners",
      schema::Unit("rad/s").AtLeast(0.01));
    v("lift_time_s", lift_time_s, "waiting in a lift between floors",
      schema::Unit("s").Within(0, 3600));
    v("session_gap_s", session_gap_s, "time between sessions", schema::Unit("s").Within(0, 86400));
  }
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
