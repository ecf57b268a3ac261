#include "common/geometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "common/circular.h"

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

TEST(AlignRigid2DTest, ApplyMovesTheEstimateOntoTheTruthAndBack) {
  const std::vector<Point2> truth = {{0, 0}, {4, 0}, {4, 3}, {1, 7}};
  const std::vector<Point2> estimate = {{5, 1}, {5, 5}, {2, 5}, {-2, 2}};  // truth turned 90 deg
  auto a = AlignRigid2D(estimate, truth);
  ASSERT_TRUE(a.has_value());
  for (size_t i = 0; i < truth.size(); ++i) {
    const Point2 on_truth = Apply(*a, estimate[i]);
    EXPECT_NEAR(on_truth.x, truth[i].x, 1e-12);
    EXPECT_NEAR(on_truth.y, truth[i].y, 1e-12);
    const Point2 back = ApplyInverse(*a, truth[i]);
    EXPECT_NEAR(back.x, estimate[i].x, 1e-12);
    EXPECT_NEAR(back.y, estimate[i].y, 1e-12);
  }
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

namespace ratslam {
namespace {

// WrapAngleNear must be WrapAngle bit for bit: the hot loops use it, the rest WrapAngle. The
// oracle is fmod-based; the inputs cover the fast range, its edges and beyond.
TEST(WrapAngleNearTest, EqualsWrapAngleBitForBit) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> wide(-12.0, 12.0);
  std::vector<double> inputs = {0.0,
                                -0.0,
                                M_PI,
                                -M_PI,
                                2 * M_PI,
                                -2 * M_PI,
                                3 * M_PI,
                                -3 * M_PI,
                                1e-300,
                                -1e-300,
                                1e9,
                                -1e9,
                                std::nextafter(3 * M_PI, 0.0)};
  for (int i = 0; i < 1000000; ++i) inputs.push_back(wide(rng));
  for (double x : inputs) {
    const double a = WrapAngle(x);
    const double b = WrapAngleNear(x);
    ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0) << std::hexfloat << x << " -> " << a << " vs " << b;
  }
  EXPECT_TRUE(std::isnan(WrapAngleNear(std::nan(""))));
}

// SinCosOfSmallAngle against libm's sin and cos: within 2 ulp of them on both series ranges,
// their edges, tiny and subnormal angles, and exactly sincos beyond 1/16 (and for NaN).
TEST(SinCosOfSmallAngleTest, AgreesWithLibmWithinTwoUlp) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> small(-0.0625, 0.0625);
  std::uniform_real_distribution<double> exponent(-60.0, -4.0);
  std::vector<double> inputs = {0.0,    -0.0,    0x1p-10, -0x1p-10, std::nextafter(0x1p-10, 1.0),
                                0.0625, -0.0625, 1e-300,  4.9e-324, std::nextafter(0.0625, 1.0),
                                0.5,    -3.0,    100.0};
  for (int i = 0; i < 200000; ++i) {
    inputs.push_back(small(rng));
    const double tiny = std::exp2(exponent(rng));
    inputs.push_back(i % 2 ? tiny : -tiny);
  }
  auto ulps = [](double got, double want) {
    return std::abs(got - want) / (std::nextafter(std::abs(want), INFINITY) - std::abs(want));
  };
  for (double x : inputs) {
    double s, c;
    SinCosOfSmallAngle(x, &s, &c);
    ASSERT_LE(ulps(s, std::sin(x)), 2.0) << std::hexfloat << x;
    ASSERT_LE(ulps(c, std::cos(x)), 2.0) << std::hexfloat << x;
    if (std::abs(x) > 0.0625) {
      double ls, lc;
      ::sincos(x, &ls, &lc);
      EXPECT_EQ(s, ls);
      EXPECT_EQ(c, lc);
    }
  }
  double s, c;
  SinCosOfSmallAngle(std::nan(""), &s, &c);
  EXPECT_TRUE(std::isnan(s) && std::isnan(c));
}

}  // namespace
}  // namespace ratslam
