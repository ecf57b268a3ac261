#include "fusion/wifi_sequence/wifi_sequence.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include "common/random.h"

namespace ratslam::wifi_sequence {
namespace {

SparseSignal Signal(std::vector<std::pair<uint32_t, double>> v) { return v; }

TEST(WifiSequenceOptionsTest, DefaultsAreValidAndFollowThePaper) {
  WifiSequenceOptions o;
  std::string error;
  EXPECT_TRUE(o.IsValid(&error)) << error;
  EXPECT_EQ(o.smoothing_tau_m, 1.5);  // section III-B.2
  EXPECT_EQ(o.dp_alpha, 1.1);         // section III-C.1
  EXPECT_EQ(o.confidence_sigmas, 3.0);
  o.min_sequence_poses = 300;
  EXPECT_FALSE(o.IsValid(&error));
}

TEST(SignalQualityTest, IsEquationOne) {
  EXPECT_DOUBLE_EQ(SignalQuality(-70.0, -100.0), 60.0);  // SQ = 2 (RSSI + 100)
  EXPECT_DOUBLE_EQ(SignalQuality(-120.0, -100.0), 0.0);
  EXPECT_DOUBLE_EQ(SignalQuality(-30.0, -100.0), 100.0);
}

TEST(SmoothedSignalMatrixTest, WeightsSumToOneAndFallWithTravel) {
  SmoothedSignalMatrix m(1.5, 4.0);
  for (int i = 0; i < 20; ++i) m.Add(0.7 * i, Signal({{0, 10.0 + i}}));
  for (size_t t : {0u, 5u, 10u, 19u}) {
    const auto w = m.Weights(t);
    double sum = 0.0;
    for (const auto& [i, v] : w) sum += v;
    EXPECT_NEAR(sum, 1.0, 1e-12) << "row " << t;  // eq. 4
    // Weights fall with the travel from pose t, on both sides (eq. 3).
    for (size_t k = 1; k < w.size(); ++k) {
      const double d_prev = std::abs(m.Travel(w[k - 1].first) - m.Travel(t));
      const double d_here = std::abs(m.Travel(w[k].first) - m.Travel(t));
      if (d_here > d_prev) {
        EXPECT_LT(w[k].second, w[k - 1].second);
      }
      if (d_here < d_prev) {
        EXPECT_GT(w[k].second, w[k - 1].second);
      }
    }
    // Beyond the cutoff (4 tau = 6 m) nothing counts.
    for (const auto& [i, v] : w) EXPECT_LE(std::abs(m.Travel(i) - m.Travel(t)), 6.0 + 1e-12);
  }
}

// An independent oracle: eqs. 2-4 computed for a whole matrix at once, dense.
std::vector<std::vector<double>> DenseSmoothed(const std::vector<double>& travel,
                                               const std::vector<std::vector<double>>& s,
                                               double tau, double cutoff) {
  std::vector<std::vector<double>> out(s.size(), std::vector<double>(s[0].size(), 0.0));
  for (size_t t = 0; t < s.size(); ++t) {
    double total = 0.0;
    for (size_t i = 0; i < s.size(); ++i) {
      const double d = std::abs(travel[t] - travel[i]);
      if (d > cutoff) continue;
      const double w = std::exp(-d * d / (2 * tau * tau));
      total += w;
      for (size_t n = 0; n < s[i].size(); ++n) out[t][n] += w * s[i][n];
    }
    for (double& v : out[t]) v /= total;
  }
  return out;
}

TEST(SmoothedSignalMatrixTest, IncrementalRowsEqualAFullRecomputation) {
  Random random(7);
  const size_t poses = 60, aps = 9;
  std::vector<double> travel;
  std::vector<std::vector<double>> dense;
  SmoothedSignalMatrix m(1.5, 4.0);
  double d = 0.0;
  for (size_t t = 0; t < poses; ++t) {
    d += random.Uniform(0.0, 2.0);
    travel.push_back(d);
    std::vector<double> row(aps, 0.0);
    SparseSignal sparse;
    for (uint32_t n = 0; n < aps; ++n) {
      if (random.Uniform() < 0.5) continue;
      row[n] = random.Uniform(1.0, 100.0);
      sparse.emplace_back(n, row[n]);
    }
    dense.push_back(row);
    m.Add(d, sparse);
  }
  const auto oracle = DenseSmoothed(travel, dense, 1.5, 6.0);
  for (size_t t = 0; t < poses; ++t) {
    std::vector<double> row(aps, 0.0);
    for (const auto& [n, v] : m.Smoothed(t)) row[n] = v;
    for (size_t n = 0; n < aps; ++n) EXPECT_NEAR(row[n], oracle[t][n], 1e-9) << t << "," << n;
    // Cosine similarity against the oracle's rows.
    for (size_t j : {size_t{0}, poses / 2, poses - 1}) {
      double dot = 0, a = 0, b = 0;
      for (size_t n = 0; n < aps; ++n) {
        dot += oracle[t][n] * oracle[j][n];
        a += oracle[t][n] * oracle[t][n];
        b += oracle[j][n] * oracle[j][n];
      }
      EXPECT_NEAR(m.Similarity(t, j), dot / std::sqrt(a * b), 1e-9);
    }
    EXPECT_NEAR(m.Similarity(t, t), 1.0, 1e-12);
  }
}

TEST(SmoothedSignalMatrixTest, APoseWithNothingHeardNearbyHasZeroSimilarity) {
  SmoothedSignalMatrix m(1.5, 4.0);
  m.Add(0.0, Signal({{0, 50.0}}));
  m.Add(100.0, Signal({}));
  EXPECT_EQ(m.Similarity(0, 1), 0.0);
  EXPECT_EQ(m.Similarity(1, 1), 0.0);
}

TEST(ContinuousDpTest, FindsAPlantedSubsequenceWithoutCrossing) {
  // PS of 40 poses, CS = PS poses 12..29 with every other pose skipped in the middle (a faster
  // walk there).
  const size_t cols = 40;
  std::vector<size_t> truth;
  for (size_t j = 12; j < 18; ++j) truth.push_back(j);
  for (size_t j = 19; j < 26; j += 2) truth.push_back(j);
  for (size_t j = 26; j < 30; ++j) truth.push_back(j);
  const size_t rows = truth.size();
  // Cost grows with the distance between the poses, as inverse smoothed similarity does.
  std::vector<double> cost(rows * cols);
  for (size_t i = 0; i < rows; ++i) {
    for (size_t j = 0; j < cols; ++j) {
      cost[i * cols + j] = 1.0 + 3.0 * std::abs(static_cast<double>(j) - truth[i]);
    }
    // Decoys as cheap as the truth that a crossing assignment would take.
    if (cols - 1 - i != truth[i]) cost[i * cols + (cols - 1 - i)] = 1.0;
  }
  StatusOr<DpMatch> match = ContinuousDpMatch(cost, rows, cols, 1.1);
  ASSERT_TRUE(match.ok()) << match.status().message();
  ASSERT_EQ(match.value().pairs.size(), rows);
  for (size_t i = 0; i < rows; ++i) {
    EXPECT_EQ(match.value().pairs[i].current, i);
    EXPECT_EQ(match.value().pairs[i].past, truth[i]) << "row " << i;
    if (i > 0) {
      EXPECT_GE(match.value().pairs[i].past, match.value().pairs[i - 1].past);
    }
  }
}

TEST(ContinuousDpTest, NoPairsCrossOnRandomCosts) {
  Random random(3);
  for (int trial = 0; trial < 20; ++trial) {
    const size_t rows = 5 + trial, cols = 3 * rows;
    std::vector<double> cost(rows * cols);
    for (double& c : cost) c = random.Uniform(1.0, 20.0);
    StatusOr<DpMatch> match = ContinuousDpMatch(cost, rows, cols, 1.1);
    ASSERT_TRUE(match.ok());
    for (size_t i = 1; i < rows; ++i) {
      EXPECT_GE(match.value().pairs[i].past, match.value().pairs[i - 1].past);
      // Slope limits of eq. 5: at most 3 columns per row.
      EXPECT_LE(match.value().pairs[i].past - match.value().pairs[i - 1].past, 5u);
    }
  }
}

TEST(ContinuousDpTest, RefusesBadInput) {
  EXPECT_FALSE(ContinuousDpMatch({}, 0, 0, 1.1).ok());
  EXPECT_FALSE(ContinuousDpMatch({1.0, NAN}, 1, 2, 1.1).ok());
  EXPECT_FALSE(ContinuousDpMatch({1.0, 2.0}, 2, 2, 1.1).ok());  // wrong size
  // Ten rows cannot fit in two columns (slope at most 3).
  EXPECT_FALSE(ContinuousDpMatch(std::vector<double>(20, 1.0), 10, 2, 1.1).ok());
  StatusOr<DpMatch> one = ContinuousDpMatch({3.0, 1.0, 2.0}, 1, 3, 1.1);
  ASSERT_TRUE(one.ok());
  EXPECT_EQ(one.value().pairs[0].past, 1u);
}

std::vector<Point2> Moved(const std::vector<Point2>& p, double angle, double tx, double ty) {
  std::vector<Point2> out;
  for (const Point2& q : p) {
    out.push_back({std::cos(angle) * q.x - std::sin(angle) * q.y + tx,
                   std::sin(angle) * q.x + std::cos(angle) * q.y + ty});
  }
  return out;
}

std::vector<Point2> LShape() {
  std::vector<Point2> p;
  for (int i = 0; i < 15; ++i) p.push_back({1.0 * i, 0.0});
  for (int i = 1; i < 10; ++i) p.push_back({14.0, 1.0 * i});
  return p;
}

TEST(VerifyCorrespondencesTest, RecoversAKnownTransform) {
  const std::vector<Point2> current = LShape();
  const std::vector<Point2> past = Moved(current, 0.4, 5.0, -3.0);
  const Verification v = VerifyCorrespondences(current, past, WifiSequenceOptions());
  EXPECT_EQ(v.inliers, current.size());
  EXPECT_NEAR(v.transform.rotation_rad, 0.4, 1e-9);
  EXPECT_NEAR(v.transform.translation_x_m, 5.0, 1e-9);
  EXPECT_NEAR(v.transform.translation_y_m, -3.0, 1e-9);
}

TEST(VerifyCorrespondencesTest, RejectsPlantedOutliers) {
  const std::vector<Point2> current = LShape();
  std::vector<Point2> past = Moved(current, -0.2, 2.0, 1.0);
  Random random(11);
  for (Point2& p : past) {  // dead-reckoning noise
    p.x += random.Gaussian(0.0, 0.2);
    p.y += random.Gaussian(0.0, 0.2);
  }
  const std::set<size_t> planted = {2, 7, 16, 20};
  for (size_t k : planted) past[k].x += 8.0 + k;  // Wi-Fi mismatches
  const Verification v = VerifyCorrespondences(current, past, WifiSequenceOptions());
  for (size_t k = 0; k < current.size(); ++k) {
    EXPECT_EQ(v.inlier[k], planted.count(k) == 0) << "correspondence " << k;
  }
  EXPECT_NEAR(v.transform.rotation_rad, -0.2, 0.03);
}

TEST(VerifyCorrespondencesTest, PointsTooCloseGiveNoHypothesis) {
  const std::vector<Point2> current(10, Point2{1.0, 1.0});
  const Verification v = VerifyCorrespondences(current, current, WifiSequenceOptions());
  EXPECT_EQ(v.inliers, 0u);
}

// A building with APs on a grid; a phone hears each with a log-distance path loss and noise.
struct Building {
  std::vector<Point2> aps;
  Building() {
    for (int x = -10; x <= 60; x += 12) {
      for (int y = -10; y <= 30; y += 12) aps.push_back({1.0 * x, 1.0 * y});
    }
  }
  WifiScan Scan(const Point2& at, double time_s, Random* random) const {
    WifiScan scan;
    scan.time_s = time_s;
    for (size_t a = 0; a < aps.size(); ++a) {
      const double d = std::hypot(at.x - aps[a].x, at.y - aps[a].y);
      const double rssi = -35.0 - 25.0 * std::log10(1.0 + d) + random->Gaussian(0.0, 3.0);
      if (rssi > -90.0) scan.readings.push_back({"ap" + std::to_string(a), rssi});
    }
    return scan;
  }
};

// The true position along a 40 x 20 m rectangle after `s` metres, counter-clockwise from the
// origin.
Point2 Rectangle(double s) {
  s = std::fmod(s, 120.0);
  if (s < 40) return {s, 0};
  if (s < 60) return {40, s - 40};
  if (s < 100) return {100 - s, 20};
  return {0, 120 - s};
}

struct Walk {
  std::vector<Point2> truth;
  std::vector<SequencePose> poses;
  std::vector<WifiScan> scans;
};

// One scan per metre along `path`, with odometry whose heading drifts.
template <typename Path>
Walk MakeWalk(Path path, double length_m, double drift_rad_per_m, uint64_t seed) {
  Walk w;
  Building building;
  Random random(seed);
  Pose2 odometry;
  for (int i = 0; static_cast<double>(i) <= length_m; ++i) {
    const Point2 here = path(1.0 * i);
    if (i > 0) {
      const Point2 before = path(i - 1.0);
      const double heading = std::atan2(here.y - before.y, here.x - before.x);
      odometry.theta_rad = heading + drift_rad_per_m * i;
      odometry.x_m += std::cos(odometry.theta_rad);
      odometry.y_m += std::sin(odometry.theta_rad);
    }
    SequencePose pose;
    pose.time_s = 1.5 * i;
    pose.travel_m = 1.0 * i;
    pose.odometry = odometry;
    w.truth.push_back(here);
    w.poses.push_back(pose);
    w.scans.push_back(building.Scan(here, pose.time_s, &random));
  }
  return w;
}

std::vector<SequenceLoop> RunWalk(const Walk& w, WifiSequenceLoopCloser* closer) {
  std::vector<SequenceLoop> loops;
  std::vector<Point2> map;
  for (size_t i = 0; i < w.poses.size(); ++i) {
    map.push_back({w.poses[i].odometry.x_m, w.poses[i].odometry.y_m});
    auto loop = closer->AddPose(w.poses[i], w.scans[i], map);
    EXPECT_TRUE(loop.ok()) << loop.status().message();
    if (loop.ok() && loop.value()) loops.push_back(*loop.value());
  }
  if (auto last = closer->Flush(w.poses.back().time_s)) loops.push_back(*last);
  return loops;
}

TEST(WifiSequenceLoopCloserTest, TwoLapsCloseTheLoopWithCorrectCorrespondences) {
  const Walk w = MakeWalk(Rectangle, 240.0, 0.0005, 5);
  WifiSequenceLoopCloser closer{WifiSequenceOptions()};
  const std::vector<SequenceLoop> loops = RunWalk(w, &closer);
  size_t accepted = 0, inliers = 0, close = 0;
  for (const SequenceLoop& loop : loops) {
    if (!loop.accepted) continue;
    ++accepted;
    for (const SequenceCorrespondence& c : loop.correspondences) {
      if (!c.inlier) continue;
      ++inliers;
      const Point2& a = w.truth[c.current_pose];
      const Point2& b = w.truth[c.past_pose];
      if (std::hypot(a.x - b.x, a.y - b.y) <= 3.0) ++close;
    }
  }
  EXPECT_GE(accepted, 1u);
  EXPECT_GE(inliers, 40u);  // most of the second lap
  // Chance: a random past pose of the first lap is within 3 m of a given place ~5 % of the time.
  EXPECT_GE(static_cast<double>(close), 0.9 * static_cast<double>(inliers));
}

TEST(WifiSequenceLoopCloserTest, AWalkWithoutRevisitYieldsNoLoop) {
  // 300 m straight on: Wi-Fi changes, the map never comes back.
  const Walk w = MakeWalk([](double s) { return Point2{s * 0.2, s * 0.1}; }, 300.0, 0.0, 9);
  WifiSequenceLoopCloser closer{WifiSequenceOptions()};
  EXPECT_TRUE(RunWalk(w, &closer).empty());
  EXPECT_TRUE(closer.loops().empty());
}

TEST(WifiSequenceLoopCloserTest, ARestoredCloserContinuesBitForBit) {
  const Walk w = MakeWalk(Rectangle, 240.0, 0.0005, 5);
  WifiSequenceLoopCloser whole{WifiSequenceOptions()};
  RunWalk(w, &whole);
  // The same walk stopped half way, saved and restored into a new closer.
  WifiSequenceLoopCloser a{WifiSequenceOptions()};
  std::vector<Point2> map;
  for (size_t i = 0; i < 150; ++i) {
    map.push_back({w.poses[i].odometry.x_m, w.poses[i].odometry.y_m});
    ASSERT_TRUE(a.AddPose(w.poses[i], w.scans[i], map).ok());
  }
  WifiSequenceLoopCloser b{WifiSequenceOptions()};
  ASSERT_TRUE(b.SetState(a.state()).ok());
  for (size_t i = 150; i < w.poses.size(); ++i) {
    map.push_back({w.poses[i].odometry.x_m, w.poses[i].odometry.y_m});
    ASSERT_TRUE(b.AddPose(w.poses[i], w.scans[i], map).ok());
  }
  b.Flush(w.poses.back().time_s);
  ASSERT_EQ(b.loops().size(), whole.loops().size());
  for (size_t l = 0; l < b.loops().size(); ++l) {
    EXPECT_EQ(b.loops()[l].dp_cost, whole.loops()[l].dp_cost);
    EXPECT_EQ(b.loops()[l].transform.x_m, whole.loops()[l].transform.x_m);
    EXPECT_EQ(b.loops()[l].inliers, whole.loops()[l].inliers);
  }
  for (size_t i = 0; i < w.poses.size(); i += 17) {
    EXPECT_EQ(b.similarity().Similarity(i, 40), whole.similarity().Similarity(i, 40));
  }
}

TEST(WifiSequenceLoopCloserTest, BadInputIsAnErrorOrNoLoopNeverACrash) {
  WifiSequenceLoopCloser closer{WifiSequenceOptions()};
  SequencePose pose;
  WifiScan empty;
  // A scan with no AP and a walk of one pose.
  auto r = closer.AddPose(pose, empty, {{0.0, 0.0}});
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r.value());
  EXPECT_FALSE(closer.Flush(0.0));
  // Duplicated BSSIDs: one AP, the strongest reading.
  WifiScan twice;
  twice.readings = {{"aa", -80.0}, {"aa", -60.0}, {"bb", NAN}};
  pose.travel_m = 1.0;
  ASSERT_TRUE(closer.AddPose(pose, twice, {{0, 0}, {1, 0}}).ok());
  ASSERT_EQ(closer.state().signals[1].aps.size(), 1u);
  EXPECT_DOUBLE_EQ(closer.state().signals[1].quality[0], 80.0);
  // NaN odometry, travel going back, a map position missing or NaN: errors, nothing changes.
  SequencePose bad = pose;
  bad.odometry.x_m = NAN;
  EXPECT_FALSE(closer.AddPose(bad, twice, {{0, 0}, {1, 0}, {2, 0}}).ok());
  bad = pose;
  bad.travel_m = 0.5;
  EXPECT_FALSE(closer.AddPose(bad, twice, {{0, 0}, {1, 0}, {2, 0}}).ok());
  EXPECT_FALSE(closer.AddPose(pose, twice, {{0, 0}, {1, 0}}).ok());
  EXPECT_FALSE(closer.AddPose(pose, twice, {{0, 0}, {1, 0}, {NAN, 0}}).ok());
  EXPECT_EQ(closer.size(), 2u);
  // A state with a dangling id or a duplicated BSSID is refused.
  WifiSequenceLoopCloser::State s = closer.state();
  s.open_sequence = {7};
  EXPECT_FALSE(closer.SetState(s).ok());
  s = closer.state();
  s.bssids.push_back(s.bssids[0]);
  EXPECT_FALSE(closer.SetState(s).ok());
  s = closer.state();
  s.signals[1].aps[0] = 9;
  EXPECT_FALSE(closer.SetState(s).ok());
  EXPECT_EQ(closer.size(), 2u);
}

}  // namespace
}  // namespace ratslam::wifi_sequence
