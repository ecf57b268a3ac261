// Gaussian-process Wi-Fi maps (Kudo and Miura, "Utilizing WiFi Signals for Improving SLAM and
// Person Localization", section IV-A; equation numbers are that paper's): per access point, the
// RSSI over the plane as a GP with a squared-exponential kernel (eqs. 6-9), optionally with the
// signal-dependent variance of eqs. 10-12.
//
// This file holds the GP and its options; the per-AP grids (WifiGpMap) that `ratslam wifi-map`
// will precompute follow these choices, which the paper leaves open:
//  - Training points are binned on a grid of `bin_size_m` (mean RSSI per bin; the noise variance
//    of a bin is noise_sigma^2 / count), so that an AP heard along thousands of poses costs a
//    few hundred points; the GP itself is exact over the bins.
//  - An AP not heard at a pose counts as `unheard_rssi_dbm` there (the GP's prior mean, so
//    far from any bin the prediction returns to it), but only within `unheard_reach_m` of a bin
//    where it was heard: the GP models the heard region and its edge, not the whole building.
//  - Grids are stored only for cells within `grid_margin_m` of a bin where the AP was heard; a
//    lookup elsewhere gives the prior (unheard mean, prior variance).
//  - Eq. 12's F_s is for the paper's 0-100 signal quality SQ = 2 (RSSI + 100) (eq. 1); with
//    `signal_dependent_variance` the variance at a cell is F_s(SQ(mean)) / 4 dBm^2 (SQ units are
//    half a dB) in place of sigma_f^2 in eq. 11's kernel. Eq. 10 with that kernel needs a new
//    solve per point (F_s changes the whole K'); GaussianProcess2D::Variance scales eq. 10's
//    posterior share instead: F * (1 - e' (E + N / sigma_f^2)^-1 e), exact when F = sigma_f^2.
#ifndef RATSLAM_PHONE_GAUSSIAN_PROCESS_H_
#define RATSLAM_PHONE_GAUSSIAN_PROCESS_H_

#include <optional>
#include <string>
#include <vector>

#include "common/geometry.h"
#include "common/schema.h"
#include "common/status.h"

namespace ratslam::phone {

struct WifiGpOptions {
  double length_scale_m = 1.5;             // l of eqs. 9 and 11 (the paper's 1.5 m)
  double signal_sigma_dbm = 10.0;          // sigma_f of eq. 9
  double noise_sigma_dbm = 4.0;            // sigma_p of eq. 7
  double unheard_rssi_dbm = -100.0;        // RSSI of an AP not heard, and the GP's prior mean
  double unheard_reach_m = 3.0;            // unheard poses this close to a heard bin train the GP
  double bin_size_m = 0.75;                // training points are binned on this grid
  double cell_size_m = 1.0;                // grid cell of the precomputed maps
  double grid_margin_m = 6.0;              // cells this close to a heard bin are stored
  bool signal_dependent_variance = false;  // eqs. 10-12 instead of eq. 9's constant sigma_f
  bool fit_hyperparameters = false;        // sigma_f and sigma_p by marginal likelihood
  bool fit_length_scale = false;           // ... and l too

  bool IsValid(std::string* error) const;

  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("length_scale_m", length_scale_m, "l of eqs. 9 and 11: the kernel's length scale",
      schema::Unit("m").Within(0.01, 1000));
    v("signal_sigma_dbm", signal_sigma_dbm, "sigma_f of eq. 9: the signal's prior deviation",
      schema::Unit("dBm").Within(0.01, 1000));
    v("noise_sigma_dbm", noise_sigma_dbm, "sigma_p of eq. 7: measurement noise",
      schema::Unit("dBm").Within(0.01, 1000));
    v("unheard_rssi_dbm", unheard_rssi_dbm,
      "RSSI an AP not heard counts as, and the GP's prior mean",
      schema::Unit("dBm").Within(-200, 0));
    v("unheard_reach_m", unheard_reach_m,
      "poses where the AP was not heard train its GP only this close to where it was heard",
      schema::Unit("m").NonNegative());
    v("bin_size_m", bin_size_m, "training points are averaged on a grid of this size",
      schema::Unit("m").Within(0.01, 1000));
    v("cell_size_m", cell_size_m, "cell of the precomputed mean and variance grids",
      schema::Unit("m").Within(0.01, 1000));
    v("grid_margin_m", grid_margin_m, "grid cells this close to where an AP was heard are stored",
      schema::Unit("m").Within(0.01, 1000));
    v("signal_dependent_variance", signal_dependent_variance,
      "eqs. 10-12: the variance follows F_s of the predicted signal (converted to dBm)",
      schema::Any());
    v("fit_hyperparameters", fit_hyperparameters,
      "fit signal_sigma_dbm and noise_sigma_dbm by maximising the GP marginal likelihood of the "
      "training data (the values given are the starting point)",
      schema::Any());
    v("fit_length_scale", fit_length_scale, "with fit_hyperparameters: fit length_scale_m as well",
      schema::Any());
  }
};

// Eq. 12 on the paper's signal-quality scale (0-100): the variance of a signal of strength x.
double SignalDependentVariance(double signal_quality);

// A GP over the plane with a squared-exponential kernel and per-point noise (eqs. 7-10).
class GaussianProcess2D {
 public:
  // Fits `values` at `points` around `prior_mean`; `noise_variance[i]` is point i's. Fails on
  // sizes that differ, no point, or a non-finite value.
  static StatusOr<GaussianProcess2D> Fit(const std::vector<Point2>& points,
                                         const std::vector<double>& values,
                                         const std::vector<double>& noise_variance,
                                         double prior_mean, double signal_variance,
                                         double length_scale_m);
  // Eq. 8 and eq. 10 (with eq. 9's kernel scaled by `signal_variance` of Fit, or by
  // `signal_variance_here` when given: eq. 11's F_s at this point).
  double Mean(const Point2& p) const;
  // log p(values | points, hyper-parameters): -y'(K+N)^-1 y / 2 - log|K+N| / 2 - n log(2 pi) / 2
  // with y = values - prior_mean (Rasmussen and Williams, eq. 2.30). Fails like Fit.
  static StatusOr<double> LogMarginalLikelihood(const std::vector<Point2>& points,
                                                const std::vector<double>& values,
                                                const std::vector<double>& noise_variance,
                                                double prior_mean, double signal_variance,
                                                double length_scale_m);
  double Variance(const Point2& p, std::optional<double> signal_variance_here = std::nullopt) const;

 private:
  GaussianProcess2D() = default;
  double Kernel(const Point2& a, const Point2& b) const;  // the exponential part only
  std::vector<Point2> points_;
  std::vector<double> alpha_;     // (E + N / sigma_f^2)^-1 (S - prior), E the kernel's exponential
  std::vector<double> cholesky_;  // lower Cholesky factor of E + N / sigma_f^2, row-major
  double prior_mean_ = 0.0, signal_variance_ = 1.0, length_scale_m_ = 1.0;
};

}  // namespace ratslam::phone

#endif  // RATSLAM_PHONE_GAUSSIAN_PROCESS_H_
