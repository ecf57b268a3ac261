// One barometer reading. Its own header so that data-set code (some compiled as C++17 for ROS
// headers) can hold readings without the floor tracker's C++20 headers.
#ifndef RATSLAM_SENSORS_PRESSURE_SAMPLE_H_
#define RATSLAM_SENSORS_PRESSURE_SAMPLE_H_

namespace ratslam {

struct PressureSample {
  double time_s = 0.0;
  double pressure_hpa = 0.0;
};

}  // namespace ratslam

#endif  // RATSLAM_SENSORS_PRESSURE_SAMPLE_H_
