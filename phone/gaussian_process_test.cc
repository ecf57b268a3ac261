#include "phone/gaussian_process.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include "common/random.h"

namespace ratslam::phone {
namespace {

TEST(WifiGpOptionsTest, DefaultsAreValidAndFollowThePaper) {
  WifiGpOptions o;
  std::string error;
  EXPECT_TRUE(o.IsValid(&error)) << error;
  EXPECT_EQ(o.length_scale_m, 1.5);  // section IV-A
}

TEST(SignalDependentVarianceTest, IsEquationTwelve) {
  // Worked values of eq. 12, computed by hand (Python) from the printed constants.
  EXPECT_NEAR(SignalDependentVariance(50.0), 12.477876615772617, 1e-9);
  EXPECT_NEAR(SignalDependentVariance(80.0), 8.01929806187283, 1e-9);
  // At the ends only the linear part is left.
  EXPECT_NEAR(SignalDependentVariance(0.0), 5.18341, 1e-12);
  EXPECT_NEAR(SignalDependentVariance(100.0), 5.18341 - 0.388, 1e-12);
}

// Eqs. 8 and 10 computed directly with a dense inverse: an independent oracle.
struct Oracle {
  std::vector<Point2> p;
  std::vector<double> y, noise;
  double prior, sf2, l;
  double K(const Point2& a, const Point2& b) const {
    return sf2 * std::exp(-((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y)) / (2 * l * l));
  }
  Eigen::MatrixXd Inverse() const {
    Eigen::MatrixXd k(p.size(), p.size());
    for (size_t i = 0; i < p.size(); ++i) {
      for (size_t j = 0; j < p.size(); ++j) k(i, j) = K(p[i], p[j]) + (i == j ? noise[i] : 0);
    }
    return k.inverse();
  }
  void Predict(const Point2& q, double* mean, double* variance) const {
    const Eigen::MatrixXd inv = Inverse();
    Eigen::VectorXd k(p.size()), s(p.size());
    for (size_t i = 0; i < p.size(); ++i) {
      k(i) = K(q, p[i]);
      s(i) = y[i] - prior;
    }
    *mean = prior + k.dot(inv * s);
    *variance = sf2 - k.dot(inv * k);
  }
};

TEST(GaussianProcess2DTest, MatchesTheEquationsComputedDirectly) {
  Random rng(3);
  Oracle o{{}, {}, {}, -100.0, 100.0, 1.5};
  for (int i = 0; i < 25; ++i) {
    o.p.push_back({rng.Uniform(0, 10), rng.Uniform(0, 6)});
    o.y.push_back(rng.Uniform(-90, -40));
    o.noise.push_back(rng.Uniform(4, 20));
  }
  StatusOr<GaussianProcess2D> gp = GaussianProcess2D::Fit(o.p, o.y, o.noise, o.prior, o.sf2, o.l);
  ASSERT_TRUE(gp.ok()) << gp.status().message();
  for (int i = 0; i < 40; ++i) {
    const Point2 q{rng.Uniform(-3, 13), rng.Uniform(-3, 9)};
    double mean, variance;
    o.Predict(q, &mean, &variance);
    EXPECT_NEAR(gp->Mean(q), mean, 1e-6);
    EXPECT_NEAR(gp->Variance(q), variance, 1e-6);
  }
}

TEST(GaussianProcess2DTest, LogMarginalLikelihoodMatchesTheDenseFormula) {
  Random rng(5);
  Oracle o{{}, {}, {}, -100.0, 64.0, 2.0};
  for (int i = 0; i < 30; ++i) {
    o.p.push_back({rng.Uniform(0, 12), rng.Uniform(0, 8)});
    o.y.push_back(rng.Uniform(-90, -40));
    o.noise.push_back(rng.Uniform(4, 20));
  }
  Eigen::MatrixXd k(o.p.size(), o.p.size());
  Eigen::VectorXd y(o.p.size());
  for (size_t i = 0; i < o.p.size(); ++i) {
    y(i) = o.y[i] - o.prior;
    for (size_t j = 0; j < o.p.size(); ++j)
      k(i, j) = o.K(o.p[i], o.p[j]) + (i == j ? o.noise[i] : 0);
  }
  const double expected = -0.5 * y.dot(k.inverse() * y) - 0.5 * std::log(k.determinant()) -
                          0.5 * o.p.size() * std::log(2 * M_PI);
  StatusOr<double> lml =
      GaussianProcess2D::LogMarginalLikelihood(o.p, o.y, o.noise, o.prior, o.sf2, o.l);
  ASSERT_TRUE(lml.ok()) << lml.status().message();
  EXPECT_NEAR(*lml, expected, 1e-6 * std::abs(expected));
}

TEST(GaussianProcess2DTest, MarginalLikelihoodPrefersTheLengthScaleThatMadeTheData) {
  // Draw a field from a GP with l = 3 m (Cholesky of its covariance times seeded normals), then
  // compare the marginal likelihood at l = 1, 3 and 9 m: 3 must win.
  Random rng(11);
  std::vector<Point2> p;
  for (double x = 0; x <= 30; x += 1.5) {
    for (double y = 0; y <= 15; y += 1.5) p.push_back({x, y});
  }
  Oracle truth{p, {}, {}, -70.0, 100.0, 3.0};
  Eigen::MatrixXd k(p.size(), p.size());
  for (size_t i = 0; i < p.size(); ++i) {
    for (size_t j = 0; j < p.size(); ++j) k(i, j) = truth.K(p[i], p[j]) + (i == j ? 1e-6 : 0);
  }
  const Eigen::MatrixXd l = k.llt().matrixL();
  Eigen::VectorXd z(p.size());
  for (size_t i = 0; i < p.size(); ++i) z(i) = rng.Gaussian(0, 1);
  const Eigen::VectorXd f = l * z;
  std::vector<double> values, noise(p.size(), 4.0);
  for (size_t i = 0; i < p.size(); ++i) values.push_back(-70.0 + f(i) + rng.Gaussian(0, 2));
  auto lml = [&](double scale) {
    return GaussianProcess2D::LogMarginalLikelihood(p, values, noise, -70.0, 100.0, scale).value();
  };
  EXPECT_GT(lml(3.0), lml(1.0));
  EXPECT_GT(lml(3.0), lml(9.0));
}

TEST(GaussianProcess2DTest, InterpolatesWithinTheNoiseAndReturnsToThePriorFarAway) {
  const std::vector<Point2> p = {{0, 0}, {2, 0}, {4, 0}, {6, 0}, {8, 0}};
  const std::vector<double> y = {-50, -55, -62, -70, -80};
  const std::vector<double> noise(p.size(), 0.25);  // 0.5 dB
  StatusOr<GaussianProcess2D> gp = GaussianProcess2D::Fit(p, y, noise, -100.0, 100.0, 1.5);
  ASSERT_TRUE(gp.ok());
  for (size_t i = 0; i < p.size(); ++i) {
    EXPECT_NEAR(gp->Mean(p[i]), y[i], 3 * 0.5) << "point " << i;
    EXPECT_LT(gp->Variance(p[i]), 0.3);
  }
  EXPECT_NEAR(gp->Mean({4, 40}), -100.0, 1e-9);
  EXPECT_NEAR(gp->Variance({4, 40}), 100.0, 1e-9);
  // Variance grows away from the data (along a line leaving the last point).
  double before = gp->Variance({8, 0});
  for (double d = 0.5; d <= 8.0; d += 0.5) {
    const double v = gp->Variance({8 + d, 0});
    EXPECT_GT(v, before) << "at " << d << " m";
    before = v;
  }
  // Eq. 11's scale replaces sigma_f^2 in the prior part.
  EXPECT_NEAR(gp->Variance({4, 40}, 7.0), 7.0, 1e-9);
  EXPECT_NEAR(gp->Variance({3, 0}, 50.0), 0.5 * gp->Variance({3, 0}), 1e-9);
}

TEST(GaussianProcess2DTest, RefusesBadInput) {
  EXPECT_FALSE(GaussianProcess2D::Fit({}, {}, {}, -100, 100, 1.5).ok());
  EXPECT_FALSE(GaussianProcess2D::Fit({{0, 0}}, {-50, -60}, {1}, -100, 100, 1.5).ok());
  EXPECT_FALSE(GaussianProcess2D::Fit({{NAN, 0}}, {-50}, {1}, -100, 100, 1.5).ok());
  EXPECT_FALSE(GaussianProcess2D::Fit({{0, 0}}, {-50}, {0.0}, -100, 100, 1.5).ok());
  EXPECT_FALSE(GaussianProcess2D::Fit({{0, 0}}, {-50}, {1}, -100, 0.0, 1.5).ok());
  // Two points at the same place are fine (the noise keeps the matrix definite).
  EXPECT_TRUE(GaussianProcess2D::Fit({{0, 0}, {0, 0}}, {-50, -52}, {1, 1}, -100, 100, 1.5).ok());
}

}  // namespace
}  // namespace ratslam::phone
