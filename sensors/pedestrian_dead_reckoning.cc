#include "sensors/pedestrian_dead_reckoning.h"

#include <algorithm>
#include <cmath>

#include "common/circular.h"

namespace ratslam::sensors {
bool PdrOptions::IsValid(std::string* error) const {
  auto fail = [error](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (!schema::CheckFields(*this, error)) return false;
  if (!(baseline_s > smoothing_s)) return fail("baseline_s: must exceed smoothing_s");
  if (!(max_step_interval_s > min_step_interval_s)) {
    return fail("max_step_interval_s: must exceed min_step_interval_s");
  }
  return true;
}

std::vector<double> DetectSteps(const std::vector<AccelerometerSample>& samples,
                                const PdrOptions& options, std::vector<double>* swing_m_s2) {
  std::vector<double> steps;
  std::vector<double> peaks;
  if (samples.empty()) return steps;
  double filtered = std::hypot(samples[0].x, samples[0].y, samples[0].z);
  // The baseline follows the phone's own gravity reading (not exactly 9.81 m/s^2) slowly.
  double baseline = filtered;
  double previous_time = samples[0].time_s;
  bool in_peak = false;
  double peak_value = 0.0, peak_time = 0.0;
  double trough = filtered;  // lowest value since the last accepted peak
  std::vector<double> troughs;
  for (const AccelerometerSample& s : samples) {
    const double magnitude = std::hypot(s.x, s.y, s.z);
    const double dt = std::max(0.0, s.time_s - previous_time);
    previous_time = s.time_s;
    // First-order low-pass: alpha = dt / (tau + dt).
    const double alpha = options.smoothing_s > 0.0 ? dt / (options.smoothing_s + dt) : 1.0;
    filtered += alpha * (magnitude - filtered);
    baseline += dt / (options.baseline_s + dt) * (magnitude - baseline);
    trough = std::min(trough, filtered);
    if (filtered > baseline + options.peak_threshold_m_s2) {
      if (!in_peak || filtered > peak_value) {
        peak_value = filtered;
        peak_time = s.time_s;
      }
      in_peak = true;
    } else if (in_peak && filtered < baseline) {
      // The peak is over when the magnitude falls back below the baseline: one step at its
      // maximum.
      in_peak = false;
      if (steps.empty() || peak_time - steps.back() >= options.min_step_interval_s) {
        if (!steps.empty()) troughs.push_back(trough);  // the trough after the previous step
        steps.push_back(peak_time);
        peaks.push_back(peak_value);
        trough = filtered;
      }
    }
  }
  if (!steps.empty()) troughs.push_back(trough);
  if (swing_m_s2) {
    // Weinberg's a_max - a_min: each step's peak and the trough that follows it.
    swing_m_s2->clear();
    for (size_t i = 0; i < steps.size(); ++i) swing_m_s2->push_back(peaks[i] - troughs[i]);
  }
  return steps;
}

double OrientationSteadiness(const std::vector<AccelerometerSample>& samples, double time_s,
                             double window_s) {
  const auto by_time = [](const AccelerometerSample& s, double t) { return s.time_s < t; };
  auto it = std::lower_bound(samples.begin(), samples.end(), time_s - 0.5 * window_s, by_time);
  double x = 0.0, y = 0.0, z = 0.0, lengths = 0.0;
  for (; it != samples.end() && it->time_s <= time_s + 0.5 * window_s; ++it) {
    x += it->x;
    y += it->y;
    z += it->z;
    lengths += std::hypot(it->x, it->y, it->z);
  }
  return lengths > 0.0 ? std::hypot(x, y, z) / lengths : 1.0;
}

std::vector<Step> PedestrianDeadReckoning(const std::vector<AccelerometerSample>& accelerometer,
                                          const std::vector<HeadingSample>& headings,
                                          const PdrOptions& options, PdrReport* report) {
  std::vector<double> swings;
  const std::vector<double> times = DetectSteps(accelerometer, options, &swings);
  std::vector<Step> steps;
  if (report) *report = PdrReport{times.size(), 0};
  for (size_t i = 0; i < times.size(); ++i) {
    if (options.min_orientation_steadiness > 0.0 &&
        OrientationSteadiness(accelerometer, times[i], options.orientation_window_s) <
            options.min_orientation_steadiness) {
      if (report) ++report->steps_not_walking;
      continue;
    }
    Step step;
    step.time_s = times[i];
    step.length_m = options.fixed_step_length_m > 0.0
                        ? options.fixed_step_length_m
                        : options.weinberg_k * std::pow(std::max(0.0, swings[i]), 0.25);
    // Heading at the step, interpolated along the shorter arc.
    double heading = 0.0;
    if (!headings.empty()) {
      auto after = std::lower_bound(headings.begin(), headings.end(), step.time_s,
                                    [](const HeadingSample& h, double t) { return h.time_s < t; });
      if (after == headings.end()) {
        heading = headings.back().heading_rad;
      } else if (after == headings.begin() || after->time_s == step.time_s) {
        heading = after->heading_rad;
      } else {
        const HeadingSample& a = *(after - 1);
        const double f = (step.time_s - a.time_s) / (after->time_s - a.time_s);
        heading = a.heading_rad + f * WrapAngle(after->heading_rad - a.heading_rad);
      }
    }
    step.heading_rad = WrapAngle(heading + options.heading_offset_rad);
    steps.push_back(step);
  }
  return steps;
}

}  // namespace ratslam::sensors
