#include "sensors/pedestrian_dead_reckoning.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/random.h"

namespace ratslam {
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

}  // namespace
}  // namespace ratslam
