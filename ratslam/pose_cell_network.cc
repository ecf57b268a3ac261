#include "ratslam/pose_cell_network.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/circular.h"

// The fuzz build (clang, -fsanitize=fuzzer-no-link) leaves the numeric kernels below without
// coverage callbacks; the sanitizers stay. Their branches are loop bounds over the activity box,
// not decisions about the input, and the callbacks cost more than the work: the map-file fuzzer
// spent 70 % of its time in them inside ConvolveAxis (6 inputs a second). An attribute rather
// than -fsanitize-coverage-ignorelist, whose file path ccache would hash as it stands, so that
// no clone in another folder would hit the cache.
#if defined(RATSLAM_FUZZ_BUILD) && defined(__clang__)
#define RATSLAM_NO_COVERAGE __attribute__((no_sanitize("coverage")))
#else
#define RATSLAM_NO_COVERAGE
#endif

namespace ratslam {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// 1D factor of a normalised separable Gaussian: exp(-d^2 / (2 variance)), summing to 1. The
// product of three such factors is the 3D kernel, also summing to 1.
std::vector<double> GaussianFactor(int size, double variance) {
  std::vector<double> kernel(size);
  const int radius = size / 2;
  double sum = 0.0;
  for (int i = 0; i < size; ++i) {
    const double d = i - radius;
    kernel[i] = std::exp(-d * d / (2.0 * variance));
    sum += kernel[i];
  }
  for (double& w : kernel) w /= sum;
  return kernel;
}

// Circular mean of positions in [0, size) weighted by `weights`.
double CircularMean(const std::complex<double>& sum, double size) {
  return WrapCoordinate(std::arg(sum) / kTwoPi * size, size);
}

}  // namespace

bool PoseCellOptions::IsValid(std::string* error) const {
  if (!schema::CheckFields(*this, error)) return false;
  // Three buffers of doubles per cell: 2^24 cells need 384 MiB; 2^30 needed 24 GiB and passed.
  if (static_cast<long long>(dim_xy_cells) * dim_xy_cells * dim_theta_cells > kMaxPoseCells) {
    if (error)
      *error = "dim_xy_cells: grid of dim_xy_cells^2 x dim_theta_cells larger than 2^24 cells";
    return false;
  }
  // A kernel wider than the (wrapping) grid adds each cell to itself several times and costs
  // size^3 per active cell: 100001 once ran for minutes.
  const int smallest = std::min(dim_xy_cells, dim_theta_cells);
  for (const auto& [name, size] :
       {std::pair<const char*, int>{"excitation_size_cells", excitation_size_cells},
        {"inhibition_size_cells", inhibition_size_cells}}) {
    if (size > smallest) {
      if (error) {
        *error = std::string(name) + ": " + std::to_string(size) +
                 " is wider than the grid (at most min(dim_xy_cells, dim_theta_cells) = " +
                 std::to_string(smallest) + ")";
      }
      return false;
    }
  }
  // A cell so small that a metre of travel is more than 2^40 cells makes the poses meaningless.
  if (cell_size_m < 1e-9) {
    if (error) *error = "cell_size_m: must be at least 1e-9 m";
    return false;
  }
  return true;
}

double TurnedTheta(double theta, double turn_rad, int dim_theta) {
  return WrapCoordinate(theta + turn_rad / (2.0 * std::numbers::pi) * dim_theta, dim_theta);
}

double PoseCellDistance(const PoseCellPosition& a, const PoseCellPosition& b, int dim_xy,
                        int dim_theta) {
  const double dx = CircularDifference(a.x, b.x, dim_xy);
  const double dy = CircularDifference(a.y, b.y, dim_xy);
  const double dt = CircularDifference(a.theta, b.theta, dim_theta);
  return std::sqrt(dx * dx + dy * dy + dt * dt);
}

PoseCellNetwork::PoseCellNetwork(const PoseCellOptions& options) : options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("PoseCellOptions: " + error);
  dim_x_ = dim_y_ = options.dim_xy_cells;
  dim_t_ = options.dim_theta_cells;
  excitation_kernel_ =
      GaussianFactor(options.excitation_size_cells, options.excitation_variance_cells2);
  inhibition_kernel_ =
      GaussianFactor(options.inhibition_size_cells, options.inhibition_variance_cells2);
  const size_t cells = static_cast<size_t>(dim_x_) * dim_y_ * dim_t_;
  activity_.assign(cells, 0.0);
  scratch_a_.assign(cells, 0.0);
  scratch_b_.assign(cells, 0.0);
  residual_x_.assign(dim_t_, 0.0);
  residual_y_.assign(dim_t_, 0.0);
  for (int i = 0; i < dim_x_; ++i) phasors_x_.push_back(std::polar(1.0, kTwoPi * i / dim_x_));
  for (int i = 0; i < dim_t_; ++i) phasors_t_.push_back(std::polar(1.0, kTwoPi * i / dim_t_));
  marks_scratch_[0].assign(dim_x_, 0);
  marks_scratch_[1].assign(dim_y_, 0);
  marks_scratch_[2].assign(dim_t_, 0);
  Reset({dim_x_ / 2.0, dim_y_ / 2.0, 0.0});
}

template <typename Fn>
RATSLAM_NO_COVERAGE void PoseCellNetwork::ForEachInBox(const Box& box, Fn&& fn) const {
  // Wrapped coordinates advance incrementally: no division per cell.
  int t = box[2].start;
  for (int it = 0; it < box[2].length; ++it) {
    int y = box[1].start;
    for (int iy = 0; iy < box[1].length; ++iy) {
      const int row = Index(0, y, t);
      int x = box[0].start;
      for (int ix = 0; ix < box[0].length; ++ix) {
        fn(x, y, t, row + x);
        if (++x == dim_x_) x = 0;
      }
      if (++y == dim_y_) y = 0;
    }
    if (++t == dim_t_) t = 0;
  }
}

void PoseCellNetwork::ZeroBox(const Box& box, std::vector<double>& buffer) const {
  ForEachInBox(box, [&buffer](int, int, int, int index) { buffer[index] = 0.0; });
}

void PoseCellNetwork::Reset(const PoseCellPosition& position) {
  ZeroBox(box_, activity_);
  const int t = WrapIndex(std::lround(position.theta), dim_t_);
  const int x = WrapIndex(std::lround(position.x), dim_x_);
  const int y = WrapIndex(std::lround(position.y), dim_y_);
  residual_theta_ = CircularDifference(position.theta, t, dim_t_);
  // Every layer shares the sub-cell offset, so activity that spreads across layers keeps it.
  std::fill(residual_x_.begin(), residual_x_.end(), CircularDifference(position.x, x, dim_x_));
  std::fill(residual_y_.begin(), residual_y_.end(), CircularDifference(position.y, y, dim_y_));
  activity_[Index(x, y, t)] = 1.0;
  box_ = {Interval{x, 1}, Interval{y, 1}, Interval{t, 1}};
}

RATSLAM_NO_COVERAGE PoseCellNetwork::Box PoseCellNetwork::ConvolveAxis(
    const std::vector<double>& kernel, int axis, const Box& in_box, const std::vector<double>& in,
    std::vector<double>& out, bool grow) const {
  const int sizes[3] = {dim_x_, dim_y_, dim_t_};
  const int strides[3] = {1, dim_x_, dim_x_ * dim_y_};
  const int n = sizes[axis];
  const int radius = static_cast<int>(kernel.size()) / 2;
  const Interval in_interval = in_box[axis];
  Box out_box = in_box;
  Interval& out_interval = out_box[axis];
  if (!grow) {
    out_interval = in_interval;
  } else if (in_interval.length + 2 * radius >= n) {
    out_interval = {0, n};
  } else {
    out_interval = {WrapIndex(in_interval.start - radius, n), in_interval.length + 2 * radius};
  }
  // offsets[j] is the memory offset of axis position out.start - radius + j.
  std::vector<int>& offsets = offsets_scratch_;
  offsets.resize(out_interval.length + 2 * radius);
  line_scratch_.resize(offsets.size());
  acc_scratch_.resize(offsets.size());
  for (size_t j = 0; j < offsets.size(); ++j) {
    offsets[j] =
        WrapIndex(static_cast<long long>(out_interval.start) - radius + static_cast<long long>(j),
                  n) *
        strides[axis];
  }
  const int other_a = axis == 0 ? 1 : 0;
  const int other_b = axis == 2 ? 1 : 2;
  const int ksize = static_cast<int>(kernel.size());
  const double* weights = kernel.data();
  for (int ib = 0; ib < in_box[other_b].length; ++ib) {
    const int b = (in_box[other_b].start + ib) % sizes[other_b];
    for (int ia = 0; ia < in_box[other_a].length; ++ia) {
      const int a = (in_box[other_a].start + ia) % sizes[other_a];
      const int base = a * strides[other_a] + b * strides[other_b];
      const double* src = in.data() + base;
      double* dst = out.data() + base;
      // Gather the (wrapped) input line, then accumulate tap by tap over the whole output line:
      // the inner loop has no dependency chain and vectorises; each output still sums its taps
      // in kernel order.
      double* line = line_scratch_.data();
      double* acc = acc_scratch_.data();
      for (size_t j = 0; j < offsets.size(); ++j) line[j] = src[offsets[j]];
      for (int o = 0; o < out_interval.length; ++o) acc[o] = 0.0;
      for (int k = 0; k < ksize; ++k) {
        const double w = weights[k];
        const double* shifted = line + k;
        for (int o = 0; o < out_interval.length; ++o) acc[o] += w * shifted[o];
      }
      for (int o = 0; o < out_interval.length; ++o) dst[offsets[o + radius]] = acc[o];
    }
  }
  return out_box;
}

PoseCellNetwork::Box PoseCellNetwork::SupportOf(const Box& box) const {
  std::vector<uint8_t>* marks = marks_scratch_;
  for (int axis = 0; axis < 3; ++axis) std::fill(marks[axis].begin(), marks[axis].end(), 0);
  bool any = false;
  ForEachInBox(box, [&](int x, int y, int t, int index) {
    if (activity_[index] != 0.0) {
      marks[0][x] = marks[1][y] = marks[2][t] = 1;
      any = true;
    }
  });
  Box support;
  if (!any) return support;  // all lengths zero
  for (int axis = 0; axis < 3; ++axis) {
    const std::vector<uint8_t>& m = marks[axis];
    const int n = static_cast<int>(m.size());
    // The minimal covering interval is the complement of the longest circular run of zeros.
    const int first_mark = static_cast<int>(std::find(m.begin(), m.end(), 1) - m.begin());
    int best_gap_start = 0, best_gap_length = 0, run_start = -1;
    for (int step = 1; step <= n; ++step) {
      const int i = (first_mark + step) % n;
      if (!m[i]) {
        if (run_start < 0) run_start = i;
      } else if (run_start >= 0) {
        const int length = WrapIndex(i - run_start, n);
        if (length > best_gap_length) {
          best_gap_length = length;
          best_gap_start = run_start;
        }
        run_start = -1;
      }
    }
    support[axis] = best_gap_length == 0
                        ? Interval{0, n}
                        : Interval{(best_gap_start + best_gap_length) % n, n - best_gap_length};
  }
  return support;
}

void PoseCellNetwork::Step(double forward_m, double rotation_rad) {
  // Local excitation: E = A (*) K_excitation, into scratch_a_ (three separable passes).
  const Box b1 = ConvolveAxis(excitation_kernel_, 0, box_, activity_, scratch_a_);
  ZeroBox(box_, activity_);
  const Box b2 = ConvolveAxis(excitation_kernel_, 1, b1, scratch_a_, activity_);
  ZeroBox(b1, scratch_a_);
  const Box excited = ConvolveAxis(excitation_kernel_, 2, b2, activity_, scratch_a_);
  ZeroBox(b2, activity_);

  // Local inhibition: I = E (*) K_inhibition, into activity_. Outside the excited box E is 0,
  // so E - I - global_inhibition < 0 there and the result is 0: I is needed only inside that
  // box, and as E is zero outside it at every separable stage, each pass may be clipped to it.
  const Box& inhibited = excited;
  ConvolveAxis(inhibition_kernel_, 0, excited, scratch_a_, activity_, /*grow=*/false);
  ConvolveAxis(inhibition_kernel_, 1, excited, activity_, scratch_b_, /*grow=*/false);
  ConvolveAxis(inhibition_kernel_, 2, excited, scratch_b_, activity_, /*grow=*/false);
  ZeroBox(excited, scratch_b_);

  // A = max(E - I - global_inhibition, 0).
  const double global = options_.global_inhibition;
  double total = 0.0;
  ForEachInBox(inhibited, [&](int, int, int, int index) {
    const double value = scratch_a_[index] - activity_[index] - global;
    activity_[index] = value > 0.0 ? value : 0.0;
    total += activity_[index];
  });
  ZeroBox(excited, scratch_a_);

  if (total > 0.0) {
    const double scale = 1.0 / total;
    ForEachInBox(inhibited, [&](int, int, int, int index) { activity_[index] *= scale; });
    box_ = SupportOf(inhibited);
  } else {
    // Inhibition removed everything (only possible for a perfectly flat activity): start again
    // from one cell at the centre of the region rather than dividing by zero.
    box_ = inhibited;
    const PoseCellPosition last = {WrapCoordinate(box_[0].start + box_[0].length / 2, dim_x_),
                                   WrapCoordinate(box_[1].start + box_[1].length / 2, dim_y_),
                                   WrapCoordinate(box_[2].start + box_[2].length / 2, dim_t_)};
    Reset(last);
  }

  const double forward_cells = forward_m / options_.cell_size_m;
  const double rotation_cells = rotation_rad / kTwoPi * dim_t_;
  PathIntegrate(forward_cells, rotation_cells, 0.5 * rotation_rad);
}

RATSLAM_NO_COVERAGE void PoseCellNetwork::PathIntegrate(double forward_cells, double rotation_cells,
                                                        double midpoint_rotation_rad) {
  if (forward_cells == 0.0 && rotation_cells == 0.0) return;
  // Whole-cell shifts per layer; the fractional remainder stays in the residuals.
  std::vector<int> shift_x(dim_t_, 0), shift_y(dim_t_, 0);
  for (int it = 0; it < box_[2].length; ++it) {
    const int t = (box_[2].start + it) % dim_t_;
    const double heading = kTwoPi * (t + residual_theta_) / dim_t_ + midpoint_rotation_rad;
    residual_x_[t] += forward_cells * std::cos(heading);
    residual_y_[t] += forward_cells * std::sin(heading);
    const double whole_x = std::round(residual_x_[t]);
    const double whole_y = std::round(residual_y_[t]);
    residual_x_[t] -= whole_x;
    residual_y_[t] -= whole_y;
    shift_x[t] = WrapIndex(static_cast<long long>(whole_x), dim_x_);
    shift_y[t] = WrapIndex(static_cast<long long>(whole_y), dim_y_);
  }
  residual_theta_ += rotation_cells;
  const double whole_t = std::round(residual_theta_);
  residual_theta_ -= whole_t;
  const int shift_t = WrapIndex(static_cast<long long>(whole_t), dim_t_);

  // Move every active cell; scratch_a_ is all zero here.
  ForEachInBox(box_, [&](int x, int y, int t, int index) {
    const double value = activity_[index];
    if (value == 0.0) return;
    const int nx = (x + shift_x[t]) % dim_x_;
    const int ny = (y + shift_y[t]) % dim_y_;
    const int nt = (t + shift_t) % dim_t_;
    scratch_a_[Index(nx, ny, nt)] = value;
  });
  ZeroBox(box_, activity_);
  activity_.swap(scratch_a_);
  // Residuals travel with their layer's content.
  if (shift_t != 0) {
    std::rotate(residual_x_.rbegin(), residual_x_.rbegin() + shift_t, residual_x_.rend());
    std::rotate(residual_y_.rbegin(), residual_y_.rbegin() + shift_t, residual_y_.rend());
  }
  // The moved activity lies inside the old box spread by the range of per-layer shifts.
  Box candidate = box_;
  candidate[2] = {WrapIndex(static_cast<long long>(box_[2].start) + shift_t, dim_t_),
                  box_[2].length};
  int min_sx = dim_x_, max_sx = -1, min_sy = dim_y_, max_sy = -1;
  for (int it = 0; it < box_[2].length; ++it) {
    const int t = (box_[2].start + it) % dim_t_;
    // Express shifts in a signed range so that neighbouring layers give a compact span.
    const int sx = shift_x[t] > dim_x_ / 2 ? shift_x[t] - dim_x_ : shift_x[t];
    const int sy = shift_y[t] > dim_y_ / 2 ? shift_y[t] - dim_y_ : shift_y[t];
    min_sx = std::min(min_sx, sx);
    max_sx = std::max(max_sx, sx);
    min_sy = std::min(min_sy, sy);
    max_sy = std::max(max_sy, sy);
  }
  auto spread = [](Interval iv, int lo, int hi, int n) {
    const int length = iv.length + (hi - lo);
    return length >= n ? Interval{0, n} : Interval{WrapIndex(iv.start + lo, n), length};
  };
  candidate[0] = spread(box_[0], min_sx, max_sx, dim_x_);
  candidate[1] = spread(box_[1], min_sy, max_sy, dim_y_);
  box_ = SupportOf(candidate);
}

void PoseCellNetwork::Inject(const PoseCellPosition& position, double energy) {
  const int t = WrapIndex(std::lround(position.theta - residual_theta_), dim_t_);
  const int x = WrapIndex(std::lround(position.x - residual_x_[t]), dim_x_);
  const int y = WrapIndex(std::lround(position.y - residual_y_[t]), dim_y_);
  activity_[Index(x, y, t)] += energy;
  // Grow each axis interval by the shorter way round to include the injected cell.
  const int coords[3] = {x, y, t};
  const int sizes[3] = {dim_x_, dim_y_, dim_t_};
  for (int axis = 0; axis < 3; ++axis) {
    Interval& iv = box_[axis];
    const int n = sizes[axis];
    if (iv.length == 0) {
      iv = {coords[axis], 1};
      continue;
    }
    const int after = WrapIndex(coords[axis] - iv.start, n);
    if (after < iv.length) continue;  // already inside
    const int grow_forward = after - iv.length + 1;
    const int grow_backward = n - after;
    if (grow_forward <= grow_backward) {
      iv.length += grow_forward;
    } else {
      iv = {coords[axis], iv.length + grow_backward};
    }
    if (iv.length >= n) iv = {0, n};
  }
}

PoseCellPosition PoseCellNetwork::BestPosition() const {
  int best_x = 0, best_y = 0, best_t = 0;
  double best = -1.0;
  ForEachInBox(box_, [&](int x, int y, int t, int index) {
    if (activity_[index] > best) {
      best = activity_[index];
      best_x = x;
      best_y = y;
      best_t = t;
    }
  });
  const int r = options_.decode_radius_cells;
  auto window = [r](int center, int n) {
    return 2 * r + 1 >= n ? Interval{0, n} : Interval{WrapIndex(center - r, n), 2 * r + 1};
  };
  const Box box = {window(best_x, dim_x_), window(best_y, dim_y_), window(best_t, dim_t_)};
  // Per-layer sums of the cell phasors, then one rotation by each layer's residual phasor:
  // sum over cells of a * e^{i 2 pi (x + r_t) / n} = sum_t e^{i 2 pi r_t / n} sum_{x,y} a e^{...}.
  std::complex<double> sum_x, sum_y, sum_t;
  int t = box[2].start;
  for (int it = 0; it < box[2].length; ++it) {
    std::complex<double> layer_x, layer_y;
    double layer_total = 0.0;
    int y = box[1].start;
    for (int iy = 0; iy < box[1].length; ++iy) {
      int x = box[0].start;
      const double* row = activity_.data() + Index(0, y, t);
      double row_total = 0.0;
      for (int ix = 0; ix < box[0].length; ++ix) {
        const double a = row[x];
        layer_x += a * phasors_x_[x];
        row_total += a;
        if (++x == dim_x_) x = 0;
      }
      layer_y += row_total * phasors_x_[y];  // dim_y_ == dim_x_
      layer_total += row_total;
      if (++y == dim_y_) y = 0;
    }
    if (layer_total > 0.0) {
      sum_x += layer_x * std::polar(1.0, kTwoPi * residual_x_[t] / dim_x_);
      sum_y += layer_y * std::polar(1.0, kTwoPi * residual_y_[t] / dim_y_);
      sum_t += layer_total * phasors_t_[t];
    }
    if (++t == dim_t_) t = 0;
  }
  sum_t *= std::polar(1.0, kTwoPi * residual_theta_ / dim_t_);
  return {CircularMean(sum_x, dim_x_), CircularMean(sum_y, dim_y_), CircularMean(sum_t, dim_t_)};
}

double PoseCellNetwork::TotalActivity() const {
  double total = 0.0;
  ForEachInBox(box_, [&](int, int, int, int index) { total += activity_[index]; });
  return total;
}

double PoseCellNetwork::MinActivity() const {
  return *std::min_element(activity_.begin(), activity_.end());
}

PoseCellNetwork::State PoseCellNetwork::GetState() const {
  State state;
  for (size_t i = 0; i < activity_.size(); ++i) {
    if (activity_[i] != 0.0) {
      state.active_indices.push_back(static_cast<uint32_t>(i));
      state.active_values.push_back(activity_[i]);
    }
  }
  state.residual_x_cells = residual_x_;
  state.residual_y_cells = residual_y_;
  state.residual_theta_cells = residual_theta_;
  return state;
}

Status PoseCellNetwork::SetState(const State& state) {
  if (state.active_indices.size() != state.active_values.size()) {
    return Status::Error("pose-cell state: index and value counts differ");
  }
  if (state.residual_x_cells.size() != static_cast<size_t>(dim_t_) ||
      state.residual_y_cells.size() != static_cast<size_t>(dim_t_)) {
    return Status::Error("pose-cell state: residuals do not match dim_theta_cells");
  }
  // Path integration keeps every residual within half a cell (rounding to whole cells).
  auto residual_ok = [](double r) { return std::isfinite(r) && std::abs(r) <= 0.5 + 1e-9; };
  if (!std::all_of(state.residual_x_cells.begin(), state.residual_x_cells.end(), residual_ok) ||
      !std::all_of(state.residual_y_cells.begin(), state.residual_y_cells.end(), residual_ok) ||
      !residual_ok(state.residual_theta_cells)) {
    return Status::Error("pose-cell state: a residual is not finite or exceeds half a cell");
  }
  for (size_t i = 0; i < state.active_indices.size(); ++i) {
    if (state.active_indices[i] >= activity_.size()) {
      return Status::Error("pose-cell state: cell index out of range for this grid");
    }
    if (!std::isfinite(state.active_values[i]) || state.active_values[i] < 0.0) {
      return Status::Error("pose-cell state: activity must be finite and non-negative");
    }
  }
  std::fill(activity_.begin(), activity_.end(), 0.0);
  for (size_t i = 0; i < state.active_indices.size(); ++i) {
    activity_[state.active_indices[i]] = state.active_values[i];
  }
  residual_x_ = state.residual_x_cells;
  residual_y_ = state.residual_y_cells;
  residual_theta_ = state.residual_theta_cells;
  box_ = SupportOf({Interval{0, dim_x_}, Interval{0, dim_y_}, Interval{0, dim_t_}});
  return Status::Ok();
}

}  // namespace ratslam
