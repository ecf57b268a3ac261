#include "phone/gaussian_process.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace ratslam::phone {

bool WifiGpOptions::IsValid(std::string* error) const { return schema::CheckFields(*this, error); }

double SignalDependentVariance(double x) {
  x = std::clamp(x, 0.0, 100.0);
  // Eq. 12, fitted by the paper to its receiver's signal quality (eq. 1).
  return std::pow(x, 4.59721) * std::pow(100.0 - x, 3.30446) / 2.9568824e13 * 8.32773 -
         0.00388 * x + 5.18341;
}

double GaussianProcess2D::Kernel(const Point2& a, const Point2& b) const {
  const double dx = a.x - b.x, dy = a.y - b.y;
  return std::exp(-(dx * dx + dy * dy) / (2.0 * length_scale_m_ * length_scale_m_));  // eq. 9
}

StatusOr<GaussianProcess2D> GaussianProcess2D::Fit(const std::vector<Point2>& points,
                                                   const std::vector<double>& values,
                                                   const std::vector<double>& noise_variance,
                                                   double prior_mean, double signal_variance,
                                                   double length_scale_m) {
  const size_t n = points.size();
  if (n == 0 || values.size() != n || noise_variance.size() != n) {
    return Status::Error(
        "Gaussian process: no training point, or points, values and noise "
        "differ in number");
  }
  if (!(signal_variance > 0.0) || !(length_scale_m > 0.0) || !std::isfinite(signal_variance) ||
      !std::isfinite(length_scale_m) || !std::isfinite(prior_mean)) {
    return Status::Error("Gaussian process: signal variance and length scale must be positive");
  }
  for (size_t i = 0; i < n; ++i) {
    if (!std::isfinite(points[i].x) || !std::isfinite(points[i].y) || !std::isfinite(values[i]) ||
        !(noise_variance[i] > 0.0) || !std::isfinite(noise_variance[i])) {
      return Status::Error("Gaussian process: training point " + std::to_string(i) +
                           " has a non-finite value or a noise variance that is not positive");
    }
  }
  GaussianProcess2D gp;
  gp.points_ = points;
  gp.prior_mean_ = prior_mean;
  gp.signal_variance_ = signal_variance;
  gp.length_scale_m_ = length_scale_m;
  // With E the kernel's exponential part and N the noise: K + N = sigma_f^2 (E + N / sigma_f^2).
  Eigen::MatrixXd a(n, n);
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = 0; j <= i; ++j) a(i, j) = a(j, i) = gp.Kernel(points[i], points[j]);
    a(i, i) += noise_variance[i] / signal_variance;
  }
  Eigen::LLT<Eigen::MatrixXd> llt(a);
  if (llt.info() != Eigen::Success) {
    return Status::Error("Gaussian process: the kernel matrix is not positive definite");
  }
  Eigen::VectorXd y(n);
  for (size_t i = 0; i < n; ++i) y(i) = values[i] - prior_mean;
  const Eigen::VectorXd beta = llt.solve(y);  // eq. 8: k' (K + N)^-1 S = e' beta
  gp.alpha_.assign(beta.data(), beta.data() + n);
  const Eigen::MatrixXd l = llt.matrixL();
  gp.cholesky_.assign(n * n, 0.0);  // the lower factor, row-major
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = 0; j <= i; ++j) gp.cholesky_[i * n + j] = l(i, j);
  }
  return gp;
}

StatusOr<double> GaussianProcess2D::LogMarginalLikelihood(const std::vector<Point2>& points,
                                                          const std::vector<double>& values,
                                                          const std::vector<double>& noise_variance,
                                                          double prior_mean, double signal_variance,
                                                          double length_scale_m) {
  StatusOr<GaussianProcess2D> gp =
      Fit(points, values, noise_variance, prior_mean, signal_variance, length_scale_m);
  if (!gp.ok()) return gp.status();
  // K + N = sigma_f^2 A with A = L L': y'(K+N)^-1 y = y' A^-1 y / sigma_f^2 = y' beta / sigma_f^2,
  // log|K+N| = n log sigma_f^2 + 2 sum log L_ii.
  const size_t n = points.size();
  double fit = 0.0, log_det = 0.0;
  for (size_t i = 0; i < n; ++i) {
    fit += (values[i] - prior_mean) * gp->alpha_[i];
    log_det += 2.0 * std::log(gp->cholesky_[i * n + i]);
  }
  const double nd = static_cast<double>(n);
  return -0.5 * fit / signal_variance - 0.5 * (nd * std::log(signal_variance) + log_det) -
         0.5 * nd * std::log(2.0 * std::numbers::pi);
}

double GaussianProcess2D::Mean(const Point2& p) const {
  double m = prior_mean_;
  for (size_t i = 0; i < points_.size(); ++i) m += Kernel(p, points_[i]) * alpha_[i];
  return m;
}

double GaussianProcess2D::Variance(const Point2& p, std::optional<double> here) const {
  // Eq. 10: sigma_f^2 (1 - |L^-1 e|^2), L the Cholesky factor of E + N / sigma_f^2.
  const size_t n = points_.size();
  std::vector<double> z(n);
  double share = 0.0;
  for (size_t i = 0; i < n; ++i) {
    double v = Kernel(p, points_[i]);
    for (size_t j = 0; j < i; ++j) v -= cholesky_[i * n + j] * z[j];
    z[i] = v / cholesky_[i * n + i];
    share += z[i] * z[i];
  }
  return here.value_or(signal_variance_) * std::max(0.0, 1.0 - share);
}

}  // namespace ratslam::phone
