#include "ratslam/pose_graph.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/random.h"
#include "ratslam/experience_map.h"

namespace ratslam {
namespace {

Experience At(uint32_t id, double x, double y, double theta) {
  Experience e;
  e.id = id;
  e.x_m = x;
  e.y_m = y;
  e.theta_rad = theta;
  return e;
}

// The link a perfect odometry would measure from a to b.
Link Between(uint32_t id, const Experience& a, const Experience& b) {
  Link l;
  l.id = id;
  l.from = a.id;
  l.to = b.id;
  const double dx = b.x_m - a.x_m, dy = b.y_m - a.y_m;
  l.distance_m = std::hypot(dx, dy);
  l.heading_rad = std::atan2(dy, dx) - a.theta_rad;
  l.facing_rad = b.theta_rad - a.theta_rad;
  return l;
}

// Links measured exactly from true poses (a square route driven twice, with loop closures): from
// any perturbed start the optimiser returns the true poses, the first experience held fixed.
TEST(PoseGraphTest, ConsistentLinksRecoverTheTruePoses) {
  std::vector<Experience> truth;
  for (uint32_t i = 0; i < 80; ++i) {
    const int side = (i % 40) / 10;
    const double f = (i % 10) / 10.0;
    const double corners[5][2] = {{0, 0}, {10, 0}, {10, 10}, {0, 10}, {0, 0}};
    truth.push_back(At(i, corners[side][0] + f * (corners[side + 1][0] - corners[side][0]),
                       corners[side][1] + f * (corners[side + 1][1] - corners[side][1]),
                       side * M_PI / 2 + 0.01 * i));
  }
  std::vector<Link> links;
  for (uint32_t i = 0; i + 1 < truth.size(); ++i) {
    links.push_back(Between(links.size(), truth[i], truth[i + 1]));
  }
  for (uint32_t i = 40; i < 80; i += 5)
    links.push_back(Between(links.size(), truth[i], truth[i - 40]));
  std::vector<Experience> ex = truth;
  Random rng(4);
  for (size_t i = 1; i < ex.size(); ++i) {
    ex[i].x_m += rng.Gaussian(0, 0.5);
    ex[i].y_m += rng.Gaussian(0, 0.5);
    ex[i].theta_rad += rng.Gaussian(0, 0.2);
  }
  auto result = OptimisePoseGraph(&ex, links, LinkNoise());
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_GT(result->initial_cost, 1.0);
  EXPECT_LT(result->final_cost, 1e-12);
  for (size_t i = 0; i < ex.size(); ++i) {
    EXPECT_NEAR(ex[i].x_m, truth[i].x_m, 1e-7) << i;
    EXPECT_NEAR(ex[i].y_m, truth[i].y_m, 1e-7) << i;
    EXPECT_NEAR(std::remainder(ex[i].theta_rad - truth[i].theta_rad, 2 * M_PI), 0.0, 1e-7) << i;
  }
}

// A known answer: four experiences on a line, odometry of +1 m each and a loop closure from the
// last to the first that measures 2.7 m back instead of 3. With equal information (the noise
// does not depend on length here) least squares spreads the 0.3 m misclosure evenly over the
// four links: each ends 0.075 m off, so x = 0, 0.925, 1.85, 2.775.
TEST(PoseGraphTest, MisclosureSpreadsEvenlyOverEqualLinks) {
  std::vector<Experience> ex = {At(0, 0, 0, 0), At(1, 1, 0, 0), At(2, 2, 0, 0), At(3, 3, 0, 0)};
  std::vector<Link> links;
  for (uint32_t i = 0; i < 3; ++i) links.push_back(Between(i, ex[i], ex[i + 1]));
  Link closure = Between(3, ex[3], ex[0]);
  closure.distance_m = 2.7;
  links.push_back(closure);
  LinkNoise noise;
  noise.sigma_m_per_m = 0.0;
  auto result = OptimisePoseGraph(&ex, links, noise);
  ASSERT_TRUE(result.ok());
  const double expected[4] = {0.0, 0.925, 1.85, 2.775};
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(ex[i].x_m, expected[i], 1e-9);
    EXPECT_NEAR(ex[i].y_m, 0.0, 1e-9);
    EXPECT_NEAR(ex[i].theta_rad, 0.0, 1e-9);
  }
  // Cost: four residuals of 0.075 m at information 1/0.05^2.
  EXPECT_NEAR(result->final_cost, 4 * 0.075 * 0.075 / (0.05 * 0.05), 1e-9);
}

// A part of the graph not linked to the first experience keeps its own first pose fixed; a link
// to a missing experience is an error that changes nothing.
TEST(PoseGraphTest, DisconnectedPartsAndBadLinks) {
  std::vector<Experience> ex = {At(0, 0, 0, 0), At(1, 1, 0, 0), At(2, 5, 5, 1), At(3, 7, 5, 1)};
  std::vector<Link> links = {Between(0, ex[0], ex[1]), Between(1, ex[2], ex[3])};
  links[1].distance_m = 1.0;
  auto result = OptimisePoseGraph(&ex, links, LinkNoise());
  ASSERT_TRUE(result.ok());
  EXPECT_DOUBLE_EQ(ex[2].x_m, 5.0);
  EXPECT_NEAR(std::hypot(ex[3].x_m - 5.0, ex[3].y_m - 5.0), 1.0, 1e-9);
  links.push_back(Between(2, ex[0], ex[1]));
  links.back().to = 9;
  const std::vector<Experience> before = ex;
  EXPECT_FALSE(OptimisePoseGraph(&ex, links, LinkNoise()).ok());
  EXPECT_EQ(ex[3].x_m, before[3].x_m);
}

}  // namespace
}  // namespace ratslam
