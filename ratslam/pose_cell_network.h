// The pose-cell network: a 3D continuous attractor network over (x, y, theta) that wraps in all
// three axes (Milford and Wyeth 2008; the dynamics follow OpenRatSLAM, Ball et al. 2013).
//
// Path integration is exact for any speed: every theta layer carries a sub-cell residual offset
// (and the whole network a theta residual). A step moves the activity by whole cells only, and
// the fractional remainder stays in the residual, so the packet is never blurred by interpolation.
// A cell's continuous position is its index plus the residual of its layer; decoding and
// injection use that continuous position.
//
// Cost scales with the active region: the activity outside a bounding box (a circular interval
// per axis) is zero by invariant, and every stage works inside that box only.
#ifndef RATSLAM_POSE_CELL_NETWORK_H_
#define RATSLAM_POSE_CELL_NETWORK_H_

#include <array>
#include <complex>
#include <cstdint>
#include <string>
#include <vector>

#include "common/schema.h"
#include "common/status.h"

namespace ratslam {

// Largest grid (cells) a valid configuration may ask for: a few hundred MiB of activity buffers.
inline constexpr long long kMaxPoseCells = 1LL << 24;

struct PoseCellOptions {
  int dim_xy_cells = 21;                    // cells along x and along y (the grid wraps)
  int dim_theta_cells = 36;                 // cells around the heading ring
  double cell_size_m = 1.0;                 // metres of travel per x/y cell
  int excitation_size_cells = 7;            // width of the excitation kernel, odd
  double excitation_variance_cells2 = 1.0;  // variance of the excitation Gaussian
  int inhibition_size_cells = 5;            // width of the local inhibition kernel, odd
  double inhibition_variance_cells2 = 2.0;  // variance of the inhibition Gaussian
  double global_inhibition = 2e-5;          // subtracted from every cell per step (floor 0)
  int decode_radius_cells = 3;              // half-width of the population-vector window

  // Returns true when usable; otherwise writes "field: reason" to *error.
  bool IsValid(std::string* error) const;

  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("dim_xy_cells", dim_xy_cells, "cells along x and along y; the grid wraps",
      schema::Unit("cells").AtLeast(1));
    v("dim_theta_cells", dim_theta_cells, "cells around the heading ring",
      schema::Unit("cells").AtLeast(1));
    v("cell_size_m", cell_size_m, "metres of travel per x/y cell", schema::Unit("m").Positive());
    v("excitation_size_cells", excitation_size_cells, "width of the excitation kernel",
      schema::Unit("cells").Odd().AtLeast(1));
    v("excitation_variance_cells2", excitation_variance_cells2,
      "variance of the excitation Gaussian", schema::Unit("cells^2").Positive());
    v("inhibition_size_cells", inhibition_size_cells, "width of the local inhibition kernel",
      schema::Unit("cells").Odd().AtLeast(1));
    v("inhibition_variance_cells2", inhibition_variance_cells2,
      "variance of the inhibition Gaussian", schema::Unit("cells^2").Positive());
    v("global_inhibition", global_inhibition,
      "activity subtracted from every cell each step, floored at 0",
      schema::Unit("").AtLeast(0).Below(1));
    v("decode_radius_cells", decode_radius_cells,
      "half-width of the window around the peak used for the population-vector pose",
      schema::Unit("cells").NonNegative());
  }
};

// A continuous position in the network, in cells; x, y in [0, dim_xy), theta in [0, dim_theta).
struct PoseCellPosition {
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;
};

// Distance in cells between two positions, with wrap in every axis (theta counted in cells).
double PoseCellDistance(const PoseCellPosition& a, const PoseCellPosition& b, int dim_xy,
                        int dim_theta);

// A theta coordinate (cells) turned by `turn_rad`, wrapped into [0, dim_theta).
double TurnedTheta(double theta, double turn_rad, int dim_theta);

class PoseCellNetwork {
 public:
  // Everything needed to restore the network exactly (see GetState / SetState).
  struct State {
    std::vector<uint32_t> active_indices;  // flat indices of non-zero cells, ascending
    std::vector<double> active_values;     // activity of those cells
    std::vector<double> residual_x_cells;  // per theta layer
    std::vector<double> residual_y_cells;  // per theta layer
    double residual_theta_cells = 0.0;
  };

  // `options` must be valid (IsValid); throws std::invalid_argument otherwise.
  explicit PoseCellNetwork(const PoseCellOptions& options);

  // Puts all activity in one cell at `position` (the sub-cell part goes into the residuals).
  void Reset(const PoseCellPosition& position);

  // One network update: excitation, local inhibition, global inhibition, normalisation, then
  // path integration by `forward_m` along each layer's heading and `rotation_rad` across layers.
  void Step(double forward_m, double rotation_rad);

  // Adds `energy` to the cell whose continuous position is nearest `position`.
  void Inject(const PoseCellPosition& position, double energy);

  // The decoded pose: the peak cell refined by a circular population-vector average over a
  // window of +-decode_radius_cells around it, including the layer residuals.
  PoseCellPosition BestPosition() const;

  double TotalActivity() const;
  double MinActivity() const;  // over the whole grid
  double Activity(int x, int y, int theta) const { return activity_[Index(x, y, theta)]; }
  int ActiveBoxVolume() const { return box_[0].length * box_[1].length * box_[2].length; }
  const PoseCellOptions& options() const { return options_; }
  int dim_xy() const { return options_.dim_xy_cells; }
  int dim_theta() const { return options_.dim_theta_cells; }

  State GetState() const;
  // Fails (leaving the network unchanged) when the state does not fit these options.
  Status SetState(const State& state);

 private:
  // A circular interval of one axis: cells start, start+1, ..., start+length-1 (mod size).
  struct Interval {
    int start = 0;
    int length = 0;
  };
  using Box = std::array<Interval, 3>;  // x, y, theta

  int Index(int x, int y, int theta) const { return (theta * dim_y_ + y) * dim_x_ + x; }
  // Convolves `in` (zero outside `in_box`) with a 1D kernel along `axis`, writing the result
  // into `out` over the returned box: `in_box` grown by the kernel radius, or `in_box` itself
  // (the result clipped to it) when `grow` is false.
  Box ConvolveAxis(const std::vector<double>& kernel, int axis, const Box& in_box,
                   const std::vector<double>& in, std::vector<double>& out, bool grow = true) const;
  void ZeroBox(const Box& box, std::vector<double>& buffer) const;
  // The minimal box holding every non-zero cell of activity_ inside `box`.
  Box SupportOf(const Box& box) const;
  void PathIntegrate(double forward_cells, double rotation_cells, double midpoint_rotation_rad);
  template <typename Fn>
  void ForEachInBox(const Box& box, Fn&& fn) const;

  PoseCellOptions options_;
  int dim_x_, dim_y_, dim_t_;
  std::vector<double> excitation_kernel_;  // normalised 1D factor of the separable 3D kernel
  std::vector<double> inhibition_kernel_;
  std::vector<double> activity_;
  std::vector<double> scratch_a_;  // all zero between calls
  std::vector<double> scratch_b_;  // all zero between calls
  Box box_;                        // activity_ is zero outside it
  std::vector<double> residual_x_, residual_y_;
  double residual_theta_ = 0.0;
  std::vector<std::complex<double>> phasors_x_;  // e^{i 2 pi x / dim_x}, also used for y
  std::vector<std::complex<double>> phasors_t_;  // e^{i 2 pi t / dim_theta}
  mutable std::vector<int> offsets_scratch_;
  mutable std::vector<double> line_scratch_, acc_scratch_;
  mutable std::vector<uint8_t> marks_scratch_[3];
};

}  // namespace ratslam

#endif  // RATSLAM_POSE_CELL_NETWORK_H_
