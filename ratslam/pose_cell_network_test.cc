#include "ratslam/pose_cell_network.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "common/circular.h"

namespace ratslam {
namespace {

constexpr double kPi = std::numbers::pi;

PoseCellOptions SmallOptions() {
  PoseCellOptions options;
  options.dim_xy_cells = 21;
  options.dim_theta_cells = 36;
  return options;
}

// Dense reference of the attractor dynamics (no path integration): full-grid 3D convolution
// with wrap, written independently of the separable box implementation.
std::vector<double> DenseReferenceStep(const std::vector<double>& a, const PoseCellOptions& o) {
  const int nx = o.dim_xy_cells, ny = o.dim_xy_cells, nt = o.dim_theta_cells;
  auto index = [&](int x, int y, int t) { return (t * ny + y) * nx + x; };
  auto kernel3d = [](int size, double variance) {
    std::vector<double> k(size * size * size);
    const int r = size / 2;
    double sum = 0.0;
    for (int i = 0; i < size; ++i)
      for (int j = 0; j < size; ++j)
        for (int l = 0; l < size; ++l) {
          const double d2 = (i - r) * (i - r) + (j - r) * (j - r) + (l - r) * (l - r);
          k[(i * size + j) * size + l] = std::exp(-d2 / (2.0 * variance));
          sum += k[(i * size + j) * size + l];
        }
    for (double& w : k) w /= sum;
    return k;
  };
  auto convolve = [&](const std::vector<double>& in, const std::vector<double>& k, int size) {
    std::vector<double> out(in.size(), 0.0);
    const int r = size / 2;
    for (int t = 0; t < nt; ++t)
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) {
          const double v = in[index(x, y, t)];
          if (v == 0.0) continue;
          for (int dt = -r; dt <= r; ++dt)
            for (int dy = -r; dy <= r; ++dy)
              for (int dx = -r; dx <= r; ++dx)
                out[index(WrapIndex(x + dx, nx), WrapIndex(y + dy, ny), WrapIndex(t + dt, nt))] +=
                    v * k[((dt + r) * size + (dy + r)) * size + (dx + r)];
        }
    return out;
  };
  const std::vector<double> excited = convolve(
      a, kernel3d(o.excitation_size_cells, o.excitation_variance_cells2), o.excitation_size_cells);
  const std::vector<double> inhibition =
      convolve(excited, kernel3d(o.inhibition_size_cells, o.inhibition_variance_cells2),
               o.inhibition_size_cells);
  std::vector<double> out(a.size());
  double total = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    out[i] = std::max(excited[i] - inhibition[i] - o.global_inhibition, 0.0);
    total += out[i];
  }
  for (double& v : out) v /= total;
  return out;
}

std::vector<double> Dense(const PoseCellNetwork& network) {
  std::vector<double> a;
  for (int t = 0; t < network.dim_theta(); ++t)
    for (int y = 0; y < network.dim_xy(); ++y)
      for (int x = 0; x < network.dim_xy(); ++x) a.push_back(network.Activity(x, y, t));
  return a;
}

TEST(PoseCellOptionsTest, DefaultsAreValid) {
  std::string error;
  EXPECT_TRUE(PoseCellOptions().IsValid(&error)) << error;
}

TEST(PoseCellOptionsTest, EvenKernelIsRejectedWithFieldName) {
  PoseCellOptions options;
  options.excitation_size_cells = 6;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_EQ(error.rfind("excitation_size_cells", 0), 0u) << error;
}

TEST(PoseCellNetworkTest, StepMatchesDenseReferenceIncludingWrap) {
  const PoseCellOptions options = SmallOptions();
  PoseCellNetwork network(options);
  // Two packets, one straddling the wrap in every axis.
  network.Reset({0.0, 20.0, 35.0});
  network.Inject({10.0, 10.0, 18.0}, 0.4);
  for (int step = 0; step < 5; ++step) {
    const std::vector<double> expected = DenseReferenceStep(Dense(network), options);
    network.Step(0.0, 0.0);
    const std::vector<double> actual = Dense(network);
    ASSERT_EQ(actual.size(), expected.size());
    for (size_t i = 0; i < actual.size(); ++i) {
      ASSERT_NEAR(actual[i], expected[i], 1e-12) << "step " << step << " cell " << i;
    }
  }
}

TEST(PoseCellNetworkTest, ActivityStaysNormalisedAndNonNegative) {
  PoseCellNetwork network(SmallOptions());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int step = 0; step < 300; ++step) {
    if (step % 17 == 0) network.Inject({10.0 + 5 * u(rng), 3.0, 9.0}, 0.2);
    network.Step(3.0 * u(rng), 0.5 * u(rng));
    ASSERT_NEAR(network.TotalActivity(), 1.0, 1e-9) << "step " << step;
    ASSERT_GE(network.MinActivity(), 0.0) << "step " << step;
  }
}

TEST(PoseCellNetworkTest, PacketSettlesAtItsStartingPose) {
  PoseCellNetwork network(SmallOptions());
  network.Reset({4.3, 17.6, 12.25});
  for (int i = 0; i < 50; ++i) network.Step(0.0, 0.0);
  const PoseCellPosition best = network.BestPosition();
  EXPECT_NEAR(best.x, 4.3, 1e-6);
  EXPECT_NEAR(best.y, 17.6, 1e-6);
  EXPECT_NEAR(best.theta, 12.25, 1e-6);
  EXPECT_LT(network.ActiveBoxVolume(), 21 * 21 * 36 / 10) << "activity should stay local";
}

// Path integration ends where the odometry says, at any speed and heading, across the wrap.
struct PathCase {
  double heading_cells;
  double speed_cells_per_step;
  int steps;
};

class PathIntegrationTest : public ::testing::TestWithParam<PathCase> {};

TEST_P(PathIntegrationTest, PacketEndsWhereOdometrySays) {
  const PathCase c = GetParam();
  PoseCellOptions options = SmallOptions();
  options.cell_size_m = 0.5;
  PoseCellNetwork network(options);
  const PoseCellPosition start = {3.0, 18.0, c.heading_cells};
  network.Reset(start);
  for (int i = 0; i < 20; ++i) network.Step(0.0, 0.0);  // settle the packet
  const PoseCellPosition settled = network.BestPosition();
  const double heading_rad = 2.0 * kPi * settled.theta / options.dim_theta_cells;
  for (int i = 0; i < c.steps; ++i) {
    network.Step(c.speed_cells_per_step * options.cell_size_m, 0.0);
  }
  const double distance = c.speed_cells_per_step * c.steps;
  const PoseCellPosition best = network.BestPosition();
  const double expected_x = WrapCoordinate(settled.x + distance * std::cos(heading_rad), 21);
  const double expected_y = WrapCoordinate(settled.y + distance * std::sin(heading_rad), 21);
  // 2% of the distance travelled: layers either side of the peak travel at a slightly different
  // angle, which the population vector averages (a property of the model, not of rounding).
  const double tolerance = 0.3 + 0.02 * distance;
  EXPECT_NEAR(CircularDifference(best.x, expected_x, 21), 0.0, tolerance);
  EXPECT_NEAR(CircularDifference(best.y, expected_y, 21), 0.0, tolerance);
  EXPECT_NEAR(CircularDifference(best.theta, settled.theta, 36), 0.0, 0.2);
}

INSTANTIATE_TEST_SUITE_P(
    AnySpeedAnyHeading, PathIntegrationTest,
    ::testing::Values(PathCase{0.0, 0.1, 100}, PathCase{0.0, 0.37, 60},
                      PathCase{9.0, 1.0, 25},     // 90 degrees, one cell per step
                      PathCase{4.5, 2.6, 10},     // 45 degrees, faster than one cell per step
                      PathCase{20.0, 7.3, 6},     // 200 degrees, several cells per step
                      PathCase{31.0, 0.05, 200},  // very slow: residual carries everything
                      PathCase{13.0, 15.2, 3}));  // crosses the whole grid in one step

TEST(PoseCellNetworkTest, RotationMovesPacketAcrossLayersAndWraps) {
  PoseCellNetwork network(SmallOptions());
  network.Reset({10.0, 10.0, 34.0});
  for (int i = 0; i < 10; ++i) network.Step(0.0, 0.0);
  const double per_step_rad = 2.0 * kPi / 36.0 * 0.7;  // 0.7 cells per step
  for (int i = 0; i < 20; ++i) network.Step(0.0, per_step_rad);
  const PoseCellPosition best = network.BestPosition();
  EXPECT_NEAR(CircularDifference(best.theta, WrapCoordinate(34.0 + 14.0, 36), 36), 0.0, 0.15);
  EXPECT_NEAR(best.x, 10.0, 0.1);
  EXPECT_NEAR(best.y, 10.0, 0.1);
}

TEST(PoseCellNetworkTest, BestPositionIsRightAcrossTheWrap) {
  PoseCellNetwork network(SmallOptions());
  // A packet centred exactly on the wrap: half its mass on each side of 0.
  network.Reset({20.5, 0.5, 35.5});
  for (int i = 0; i < 30; ++i) network.Step(0.0, 0.0);
  const PoseCellPosition best = network.BestPosition();
  EXPECT_NEAR(CircularDifference(best.x, 20.5, 21), 0.0, 1e-6);
  EXPECT_NEAR(CircularDifference(best.y, 0.5, 21), 0.0, 1e-6);
  EXPECT_NEAR(CircularDifference(best.theta, 35.5, 36), 0.0, 1e-6);
}

TEST(PoseCellNetworkTest, RepeatedInjectionMovesPacketToStoredPose) {
  PoseCellNetwork network(SmallOptions());
  network.Reset({3.0, 3.0, 3.0});
  for (int i = 0; i < 20; ++i) network.Step(0.0, 0.0);
  const PoseCellPosition target = {14.0, 12.0, 25.0};
  for (int i = 0; i < 40; ++i) {
    network.Inject(target, 0.15);
    network.Step(0.0, 0.0);
  }
  const PoseCellPosition best = network.BestPosition();
  EXPECT_LT(PoseCellDistance(best, target, 21, 36), 0.5);
}

TEST(PoseCellNetworkTest, StateRoundTripIsExact) {
  PoseCellNetwork a(SmallOptions());
  a.Reset({5.2, 6.7, 8.9});
  for (int i = 0; i < 7; ++i) a.Step(1.3, 0.2);
  PoseCellNetwork b(SmallOptions());
  ASSERT_TRUE(b.SetState(a.GetState()).ok());
  for (int i = 0; i < 5; ++i) {
    a.Step(0.7, -0.1);
    b.Step(0.7, -0.1);
  }
  EXPECT_EQ(Dense(a), Dense(b));
  EXPECT_EQ(a.BestPosition().x, b.BestPosition().x);
}

TEST(PoseCellNetworkTest, SetStateRejectsMismatchedGrid) {
  PoseCellNetwork a(SmallOptions());
  PoseCellOptions other = SmallOptions();
  other.dim_theta_cells = 12;
  PoseCellNetwork b(other);
  EXPECT_FALSE(b.SetState(a.GetState()).ok());
}

}  // namespace
}  // namespace ratslam
