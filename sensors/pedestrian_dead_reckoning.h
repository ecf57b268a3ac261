// Pedestrian dead reckoning for phone logs: steps detected in the accelerometer magnitude, a
// step length from the Weinberg model (L = K * (a_max - a_min)^(1/4) over the step; Weinberg,
// Analog Devices AN-602, 2002), and the heading from the phone's orientation sensor plus a
// configurable offset between where the phone points and where the walker goes.
#ifndef RATSLAM_SENSORS_PEDESTRIAN_DEAD_RECKONING_H_
#define RATSLAM_SENSORS_PEDESTRIAN_DEAD_RECKONING_H_

#include <string>
#include <vector>

#include "common/schema.h"

namespace ratslam {

struct PdrOptions {
  double smoothing_s = 0.1;          // time constant of the magnitude low-pass filter
  double baseline_s = 2.0;           // time constant of the baseline (the phone's gravity)
  double peak_threshold_m_s2 = 0.6;  // a step peak rises this far above the baseline
  double min_step_interval_s = 0.3;  // steps closer than this are one step
  double max_step_interval_s = 2.0;  // a longer gap starts a new walk (no step length carry)
  double weinberg_k = 0.48;          // K of the Weinberg step-length model
  double fixed_step_length_m = 0.0;  // > 0: use this length instead of the Weinberg model
  double heading_offset_rad = 0.0;   // walking direction minus phone heading

  bool IsValid(std::string* error) const;

  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("smoothing_s", smoothing_s, "time constant of the accelerometer magnitude low-pass, s",
      schema::Unit("s").NonNegative());
    v("baseline_s", baseline_s, "time constant of the slow baseline (the phone's gravity), s",
      schema::Unit("s").Positive());
    v("peak_threshold_m_s2", peak_threshold_m_s2,
      "a step peak rises this far above the baseline, m/s^2", schema::Unit("m/s^2").Positive());
    v("min_step_interval_s", min_step_interval_s, "steps closer in time than this are one step, s",
      schema::Unit("s").Positive());
    v("max_step_interval_s", max_step_interval_s, "longest gap between steps of one walk, s",
      schema::Unit("s").Positive());
    v("weinberg_k", weinberg_k, "K of the Weinberg step length L = K (a_max - a_min)^(1/4)",
      schema::Unit("").Positive());
    v("fixed_step_length_m", fixed_step_length_m, "> 0: every step has this length instead",
      schema::Unit("m").NonNegative());
    v("heading_offset_rad", heading_offset_rad, "walking direction minus phone heading, rad",
      schema::Unit("rad"));
  }
};

struct AccelerometerSample {
  double time_s;
  double x, y, z;  // m/s^2
};

struct HeadingSample {
  double time_s;
  double heading_rad;  // counter-clockwise from the x (east) axis
};

struct Step {
  double time_s = 0.0;
  double length_m = 0.0;
  double heading_rad = 0.0;  // walking direction at the step
};

// Detects steps in time-ordered accelerometer samples.
std::vector<double> DetectSteps(const std::vector<AccelerometerSample>& samples,
                                const PdrOptions& options,
                                std::vector<double>* swing_m_s2 = nullptr);

// Steps with lengths and headings (heading interpolated at each step's time).
std::vector<Step> PedestrianDeadReckoning(const std::vector<AccelerometerSample>& accelerometer,
                                          const std::vector<HeadingSample>& headings,
                                          const PdrOptions& options);

}  // namespace ratslam

#endif  // RATSLAM_SENSORS_PEDESTRIAN_DEAD_RECKONING_H_
