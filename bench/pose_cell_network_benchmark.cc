// Pose-cell update cost. Baseline: the straightforward dense update (scan the whole grid, scatter
// the full 3D kernels from every active cell), as OpenRatSLAM does it.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "common/circular.h"
#include "ratslam/pose_cell_network.h"

namespace ratslam {
namespace {

PoseCellOptions Grid(int xy, int theta) {
  PoseCellOptions o;
  o.dim_xy_cells = xy;
  o.dim_theta_cells = theta;
  return o;
}

void BM_PoseCellStep(benchmark::State& state) {
  PoseCellNetwork network(Grid(static_cast<int>(state.range(0)), 36));
  network.Reset({10.3, 12.7, 5.2});
  for (int i = 0; i < 50; ++i) network.Step(0.3, 0.02);  // settle into a moving packet
  for (auto _ : state) {
    network.Step(0.3, 0.02);
    benchmark::DoNotOptimize(network.BestPosition());
  }
  state.counters["box_cells"] = network.ActiveBoxVolume();
}
BENCHMARK(BM_PoseCellStep)->Arg(21)->Arg(30)->Arg(60)->Unit(benchmark::kMicrosecond);

void BM_PoseCellStepTwoPackets(benchmark::State& state) {
  PoseCellNetwork network(Grid(30, 36));
  network.Reset({5, 5, 5});
  for (int i = 0; i < 20; ++i) network.Step(0.0, 0.0);
  for (auto _ : state) {
    network.Inject({20, 22, 25}, 0.05);  // a competing packet across the grid
    network.Step(0.3, 0.02);
    benchmark::DoNotOptimize(network.BestPosition());
  }
  state.counters["box_cells"] = network.ActiveBoxVolume();
}
BENCHMARK(BM_PoseCellStepTwoPackets)->Unit(benchmark::kMicrosecond);

// Baseline: dense grid, 3D kernels scattered from each non-zero cell, full scans each stage.
class DenseBaseline {
 public:
  DenseBaseline(int xy, int theta) : nx_(xy), nt_(theta), a_(xy * xy * theta, 0.0) {
    excitation_ = Kernel(7, 1.0);
    inhibition_ = Kernel(5, 2.0);
    a_[Index(10, 12, 5)] = 1.0;
  }
  void Step() {
    std::vector<double> e = Scatter(a_, excitation_, 7);
    std::vector<double> i = Scatter(e, inhibition_, 5);
    double total = 0.0;
    for (size_t k = 0; k < a_.size(); ++k) {
      a_[k] = std::max(e[k] - i[k] - 2e-5, 0.0);
      total += a_[k];
    }
    for (double& v : a_) v /= total;
  }

 private:
  int Index(int x, int y, int t) const { return (t * nx_ + y) * nx_ + x; }
  static std::vector<double> Kernel(int size, double variance) {
    std::vector<double> k(size * size * size);
    double sum = 0;
    const int r = size / 2;
    for (int i = 0; i < size; ++i)
      for (int j = 0; j < size; ++j)
        for (int l = 0; l < size; ++l) {
          k[(i * size + j) * size + l] = std::exp(
              -((i - r) * (i - r) + (j - r) * (j - r) + (l - r) * (l - r)) / (2 * variance));
          sum += k[(i * size + j) * size + l];
        }
    for (double& w : k) w /= sum;
    return k;
  }
  std::vector<double> Scatter(const std::vector<double>& in, const std::vector<double>& k,
                              int size) const {
    std::vector<double> out(in.size(), 0.0);
    const int r = size / 2;
    for (int t = 0; t < nt_; ++t)
      for (int y = 0; y < nx_; ++y)
        for (int x = 0; x < nx_; ++x) {
          const double v = in[Index(x, y, t)];
          if (v == 0.0) continue;
          for (int dt = -r; dt <= r; ++dt)
            for (int dy = -r; dy <= r; ++dy)
              for (int dx = -r; dx <= r; ++dx)
                out[Index(WrapIndex(x + dx, nx_), WrapIndex(y + dy, nx_),
                          WrapIndex(t + dt, nt_))] +=
                    v * k[((dt + r) * size + dy + r) * size + dx + r];
        }
    return out;
  }
  int nx_, nt_;
  std::vector<double> a_;
  std::vector<double> excitation_, inhibition_;
};

void BM_PoseCellStepDenseBaseline(benchmark::State& state) {
  DenseBaseline baseline(static_cast<int>(state.range(0)), 36);
  for (int i = 0; i < 20; ++i) baseline.Step();
  for (auto _ : state) baseline.Step();
}
BENCHMARK(BM_PoseCellStepDenseBaseline)->Arg(21)->Arg(30)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace ratslam

BENCHMARK_MAIN();
