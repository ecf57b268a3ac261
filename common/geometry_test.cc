#include "common/geometry.h"

#include <gtest/gtest.h>

#include <cmath>

namespace ratslam {
namespace {

TEST(AlignRigid2DTest, RecoversKnownRotationAndTranslation) {
  std::vector<Point2> truth = {{0, 0}, {4, 0}, {4, 3}, {0, 3}, {1, 7}};
  const double angle = 0.7, tx = -3.0, ty = 12.5;
  std::vector<Point2> estimate;
  // estimate = R(-angle) (truth - t): aligning it must give back rotation +angle.
  for (const Point2& p : truth) {
    const double x = p.x - tx, y = p.y - ty;
    estimate.push_back(
        {std::cos(angle) * x + std::sin(angle) * y, -std::sin(angle) * x + std::cos(angle) * y});
  }
  auto a = AlignRigid2D(estimate, truth);
  ASSERT_TRUE(a.has_value());
  EXPECT_NEAR(a->rotation_rad, angle, 1e-12);
  EXPECT_NEAR(a->translation_x_m, tx, 1e-12);
  EXPECT_NEAR(a->translation_y_m, ty, 1e-12);
  EXPECT_NEAR(a->rmse_m, 0.0, 1e-12);
}

TEST(AlignRigid2DTest, RmseOfKnownResidual) {
  // Two points 2 m apart estimated 4 m apart (no rotation can fix scale): residual 1 m each.
  auto a = AlignRigid2D({{-2, 0}, {2, 0}}, {{-1, 0}, {1, 0}});
  ASSERT_TRUE(a.has_value());
  EXPECT_NEAR(a->rmse_m, 1.0, 1e-12);
  EXPECT_FALSE(AlignRigid2D({{0, 0}}, {{0, 0}}).has_value());
  EXPECT_FALSE(AlignRigid2D({{0, 0}, {1, 1}}, {{0, 0}}).has_value());
}

}  // namespace
}  // namespace ratslam
