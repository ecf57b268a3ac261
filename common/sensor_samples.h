// One reading of each sensor stream, as a data set holds them (dataset/dataset.h) and as the
// layers that consume them (front ends, Wi-Fi sequences, FABMAP, the simulator) take them. Plain
// values at the bottom, so that a consumer does not depend on the readers. Some data-set code is
// compiled as C++17 (for the ROS headers): keep this header C++17.
#ifndef RATSLAM_COMMON_SENSOR_SAMPLES_H_
#define RATSLAM_COMMON_SENSOR_SAMPLES_H_

#include <string>
#include <vector>

namespace ratslam {

// Velocities that hold from the previous odometry row's time to this row's time.
struct OdometryRow {
  double time_s = 0.0;
  double forward_speed_m_per_s = 0.0;
  double turn_rate_rad_per_s = 0.0;
};

struct ImageRow {
  double time_s = 0.0;
  std::string file;  // relative to the image folder
  int line = 0;      // line in images.csv, for error messages
};

struct GroundTruthRow {
  double time_s = 0.0;
  double x_m = 0.0;
  double y_m = 0.0;
  double theta_rad = 0.0;
  int floor = 0;
};

struct WifiReading {
  std::string bssid;
  double rssi_dbm = 0.0;
};

struct WifiScan {
  double time_s = 0.0;
  std::vector<WifiReading> readings;
};

struct CompassRow {
  double time_s = 0.0;
  double heading_rad = 0.0;
};

// One barometer reading (floors: sensors/barometer.h).
struct PressureSample {
  double time_s = 0.0;
  double pressure_hpa = 0.0;
};

}  // namespace ratslam

#endif  // RATSLAM_COMMON_SENSOR_SAMPLES_H_
