#include "ratslam/experience_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace ratslam {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(ExperienceMapOptionsTest, DefaultsAreValid) {
  std::string error;
  EXPECT_TRUE(ExperienceMapOptions().IsValid(&error)) << error;
}

TEST(ExperienceMapTest, LinksCarryOdometryInTheSourceFrame) {
  ExperienceMap map({});
  map.CreateExperience(0, {}, 0.0);
  map.Integrate(0.0, kPi / 2);  // turn left on the spot
  map.Integrate(2.0, 0.0);      // then 2 m forward: 2 m to the left of experience 0
  map.CreateExperience(1, {}, 1.0);
  ASSERT_EQ(map.num_links(), 1u);
  const Link& l = map.links()[0];
  EXPECT_NEAR(l.distance_m, 2.0, 1e-12);
  EXPECT_NEAR(l.heading_rad, kPi / 2, 1e-12);
  EXPECT_NEAR(l.facing_rad, kPi / 2, 1e-12);
  EXPECT_NEAR(l.duration_s, 1.0, 1e-12);
  EXPECT_NEAR(map.experience(1).x_m, 0.0, 1e-12);
  EXPECT_NEAR(map.experience(1).y_m, 2.0, 1e-12);
}

// Drives a square of side 10 m with a heading bias, then closes the loop back to experience 0.
ExperienceMap DriveBiasedSquare(const ExperienceMapOptions& options) {
  ExperienceMap map(options);
  map.CreateExperience(0, {}, 0.0);
  uint32_t template_id = 1;
  for (int side = 0; side < 4; ++side) {
    for (int step = 0; step < 10; ++step) {
      map.Integrate(1.0, 0.01);  // biased: 0.01 rad per metre of spurious turn
      if (side == 3 && step == 9) break;
      map.CreateExperience(template_id++, {}, 0.0);
    }
    map.Integrate(0.0, kPi / 2);
  }
  return map;
}

double LoopError(const ExperienceMap& map) {
  // Distance between the last experience and where the closing link says experience 0 is.
  const Experience& last = map.experiences().back();
  const Experience& first = map.experience(0);
  return std::hypot(last.x_m + std::cos(last.theta_rad) * 1.0 - first.x_m,
                    last.y_m + std::sin(last.theta_rad) * 1.0 - first.y_m);
}

TEST(ExperienceMapTest, RelaxationReducesLoopClosureError) {
  ExperienceMap map = DriveBiasedSquare({});
  const double before = LoopError(map);
  ASSERT_GT(before, 1.0);
  ASSERT_TRUE(map.LinkTo(0, 40.0).ok());
  // After the closing link the true geometry is a square: the last experience is at (0, -1)...
  for (int i = 0; i < 50; ++i) map.Relax();
  const double after = LoopError(map);
  EXPECT_LT(after, 0.25 * before) << "before " << before << " after " << after;
  EXPECT_EQ(map.links().back().loop_closure, true);
}

TEST(ExperienceMapTest, AnchoredFirstExperienceDoesNotMove) {
  ExperienceMapOptions options;
  options.anchor_first_experience = true;
  ExperienceMap map = DriveBiasedSquare(options);
  ASSERT_TRUE(map.LinkTo(0, 40.0).ok());
  for (int i = 0; i < 20; ++i) map.Relax();
  EXPECT_EQ(map.experience(0).x_m, 0.0);
  EXPECT_EQ(map.experience(0).y_m, 0.0);
  EXPECT_EQ(map.experience(0).theta_rad, 0.0);
}

TEST(ExperienceMapTest, LinkToExistingLinkedExperienceAddsNoDuplicate) {
  ExperienceMap map({});
  map.CreateExperience(0, {}, 0.0);
  map.Integrate(1.0, 0.0);
  map.CreateExperience(1, {}, 1.0);
  auto added = map.LinkTo(0, 2.0);
  ASSERT_TRUE(added.ok());
  EXPECT_FALSE(added.value());
  EXPECT_EQ(map.num_links(), 1u);
  EXPECT_EQ(map.current(), 0u);
  EXPECT_FALSE(map.LinkTo(7, 3.0).ok());
}

TEST(ExperienceMapTest, ShortestPathUsesLoopClosureShortcut) {
  ExperienceMap map = DriveBiasedSquare({});
  ASSERT_TRUE(map.LinkTo(0, 40.0).ok());
  const uint32_t last = static_cast<uint32_t>(map.num_experiences() - 1);
  const std::vector<uint32_t> path = map.ShortestPath(last, 0);
  ASSERT_EQ(path.size(), 2u);  // straight over the closing link, not around the square
  EXPECT_EQ(path.front(), last);
  EXPECT_EQ(path.back(), 0u);
  const std::vector<uint32_t> long_way = map.ShortestPath(0, 20);
  ASSERT_EQ(long_way.size(), 21u);
  EXPECT_TRUE(map.ShortestPath(0, 999).empty());
}

}  // namespace
}  // namespace ratslam

namespace ratslam {
namespace {

// Driving out along x, turning round, and coming back past the start: with a compass, the return
// link to the first experience has the facing the compass says (pi) whatever the odometry says,
// and dead reckoning continues facing the way the robot really faces.
TEST(ExperienceMapCompassTest, RevisitInOppositeDirectionUsesCompassFacing) {
  ExperienceMap map({});
  map.CreateExperience(0, {}, 0.0, 0.0);
  map.Integrate(5.0, 0.0);
  map.CreateExperience(1, {}, 1.0, 0.0);
  map.Integrate(5.0, 0.0);
  map.CreateExperience(2, {}, 2.0, 0.0);
  map.Integrate(0.0, 3.0);  // odometry says 3.0 rad; the compass says pi
  map.Integrate(10.0, 0.0);
  auto added = map.LinkTo(0, 3.0, M_PI);
  ASSERT_TRUE(added.ok());
  ASSERT_TRUE(added.value());
  const Link& closing = map.links().back();
  EXPECT_TRUE(closing.loop_closure);
  EXPECT_NEAR(std::abs(closing.facing_rad), 0.0, 1e-12);  // both experiences faced 0
  // Now at experience 0 facing pi: one more metre of travel goes to -x.
  map.Integrate(1.0, 0.0);
  double x, y, theta;
  map.CurrentPose(&x, &y, &theta);
  EXPECT_NEAR(x, -1.0, 1e-9);
  EXPECT_NEAR(std::abs(theta), M_PI, 1e-9);
}

TEST(ExperienceMapCompassTest, NewLinksTakeCompassFacing) {
  ExperienceMap map({});
  map.CreateExperience(0, {}, 0.0, 0.5);
  map.Integrate(1.0, 0.9);  // odometric turn 0.9 rad; compass says 0.3 rad
  map.CreateExperience(1, {}, 1.0, 0.8);
  EXPECT_NEAR(map.links().back().facing_rad, 0.3, 1e-12);
}

}  // namespace
}  // namespace ratslam
