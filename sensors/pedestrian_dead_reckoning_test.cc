#include "sensors/pedestrian_dead_reckoning.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/random.h"

namespace ratslam::sensors {
namespace {

// A walk: vertical acceleration g + 2.5 sin(2 pi f t) at f = 1.8 steps/s, sampled at 50 Hz, with
// sensor noise, and a stand-still before and after.
std::vector<AccelerometerSample> Walk(int steps, double f, double noise, uint64_t seed) {
  Random rng(seed);
  std::vector<AccelerometerSample> s;
  const double walk_s = steps / f;
  for (double t = 0; t < walk_s + 4.0; t += 0.02) {
    const bool walking = t >= 2.0 && t < 2.0 + walk_s;
    const double a = 9.80665 + (walking ? 2.5 * std::sin(2 * M_PI * f * (t - 2.0)) : 0.0);
    s.push_back({t, rng.Gaussian(0, noise), rng.Gaussian(0, noise), a + rng.Gaussian(0, noise)});
  }
  return s;
}

TEST(PdrOptionsTest, DefaultsAreValid) {
  std::string error;
  EXPECT_TRUE(PdrOptions().IsValid(&error)) << error;
}

TEST(PedestrianDeadReckoningTest, CountsKnownNumberOfSteps) {
  for (int steps : {10, 37, 120}) {
    const std::vector<double> found = DetectSteps(Walk(steps, 1.8, 0.15, steps), PdrOptions());
    EXPECT_EQ(static_cast<int>(found.size()), steps) << steps << " steps";
  }
  EXPECT_TRUE(DetectSteps(Walk(0, 1.8, 0.15, 1), PdrOptions()).empty());
}

TEST(PedestrianDeadReckoningTest, StepLengthAndHeading) {
  PdrOptions options;
  options.heading_offset_rad = 0.1;
  const std::vector<HeadingSample> headings = {{0.0, 1.0}, {100.0, 1.0}};
  const std::vector<Step> steps = PedestrianDeadReckoning(Walk(20, 1.8, 0.0, 2), headings, options);
  ASSERT_EQ(steps.size(), 20u);
  // Weinberg: K (a_max - a_min)^(1/4); the raw swing is 5 m/s^2, the 0.1 s low-pass leaves
  // about two thirds of it at 1.8 Hz.
  for (const Step& s : steps) {
    EXPECT_GT(s.length_m, 0.48 * std::pow(2.5, 0.25));
    EXPECT_LT(s.length_m, 0.48 * std::pow(5.0, 0.25) + 1e-9);
    EXPECT_NEAR(s.heading_rad, 1.1, 1e-12);
  }
  options.fixed_step_length_m = 0.7;
  EXPECT_EQ(PedestrianDeadReckoning(Walk(5, 1.8, 0.0, 3), headings, options)[0].length_m, 0.7);
}

// A calibration gesture, then a walk: 2 s still, 20 s of a figure eight in the air (roll and
// pitch swinging at 0.5 and 1 Hz by up to 86 and 57 degrees, with 4 m/s^2 of hand acceleration
// at 1.2 Hz), 2 s still, then `steps` steps with the phone held level.
std::vector<AccelerometerSample> GestureThenWalk(int steps, uint64_t seed) {
  Random rng(seed);
  std::vector<AccelerometerSample> s;
  const double g = 9.80665, f = 1.8;
  for (double t = 0; t < 24.0 + steps / f + 2.0; t += 0.02) {
    double x = 0.0, y = 0.0, z = g;
    if (t >= 2.0 && t < 22.0) {
      const double roll = 1.5 * std::sin(2 * M_PI * 0.5 * t);
      const double pitch = 1.0 * std::sin(2 * M_PI * 1.0 * t);
      x = -g * std::sin(pitch) + 4.0 * std::sin(2 * M_PI * 1.2 * t);
      y = g * std::sin(roll) * std::cos(pitch);
      z = g * std::cos(roll) * std::cos(pitch);
    } else if (t >= 24.0 && t < 24.0 + steps / f) {
      z += 2.5 * std::sin(2 * M_PI * f * (t - 24.0));
    }
    s.push_back({t, x + rng.Gaussian(0, 0.1), y + rng.Gaussian(0, 0.1), z + rng.Gaussian(0, 0.1)});
  }
  return s;
}

TEST(PedestrianDeadReckoningTest, OrientationSteadinessOfKnownSignals) {
  // Gravity fixed in the phone: 1 whatever the vertical bounce.
  EXPECT_NEAR(OrientationSteadiness(Walk(20, 1.8, 0.0, 1), 5.0, 2.0), 1.0, 1e-12);
  // Half the samples along x, half along z, equal lengths: |(1, 0, 1)| / 2 = 0.7071.
  std::vector<AccelerometerSample> two = {{0.0, 9.8, 0, 0}, {0.1, 0, 0, 9.8}};
  EXPECT_NEAR(OrientationSteadiness(two, 0.05, 1.0), std::sqrt(0.5), 1e-12);
  // The window is [t - w/2, t + w/2]: only the second sample.
  EXPECT_NEAR(OrientationSteadiness(two, 0.3, 0.4), 1.0, 1e-12);
  EXPECT_EQ(OrientationSteadiness(two, 10.0, 1.0), 1.0);  // no sample: no evidence
}

// A planted calibration gesture fools the magnitude detector (the test would be vacuous
// otherwise) and is not counted as walking; the walk after it is counted in full.
TEST(PedestrianDeadReckoningTest, CalibrationGestureIsNotCountedAsSteps) {
  const std::vector<AccelerometerSample> samples = GestureThenWalk(40, 7);
  const std::vector<HeadingSample> headings = {{0.0, 0.0}};
  PdrOptions off;
  off.min_orientation_steadiness = 0.0;
  const std::vector<Step> all = PedestrianDeadReckoning(samples, headings, off);
  const auto during_gesture = [](const std::vector<Step>& steps) {
    return std::count_if(steps.begin(), steps.end(), [](const Step& s) { return s.time_s < 23.0; });
  };
  EXPECT_GE(during_gesture(all), 10) << "the planted gesture should look like steps";
  PdrReport report;
  const std::vector<Step> kept = PedestrianDeadReckoning(samples, headings, PdrOptions(), &report);
  EXPECT_EQ(during_gesture(kept), 0);
  EXPECT_EQ(static_cast<int>(kept.size()), 40);
  EXPECT_EQ(report.steps_detected, all.size());
  EXPECT_EQ(report.steps_not_walking, all.size() - kept.size());
}

}  // namespace
}  // namespace ratslam::sensors
