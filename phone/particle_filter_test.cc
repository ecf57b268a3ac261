#include "phone/particle_filter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <vector>

namespace ratslam::phone {
namespace {

TEST(ParticleFilterOptionsTest, DefaultsAreValid) {
  std::string error;
  EXPECT_TRUE(ParticleFilterOptions().IsValid(&error)) << error;
  EXPECT_EQ(ParticleFilterOptions().candidates, 12);  // section IV-C.2
  for (ScanLikelihood l : {ScanLikelihood::kSum, ScanLikelihood::kProduct}) {
    EXPECT_EQ(ScanLikelihoodFromString(ToString(l)).value(), l);
  }
  EXPECT_FALSE(ScanLikelihoodFromString("mean").ok());
}

TEST(SystematicResampleTest, DrawsEachIndexInProportionToItsWeight) {
  const std::vector<double> w = {0.1, 0.0, 0.6, 0.3};
  for (double u : {0.0, 0.37, 0.99}) {
    const std::vector<size_t> pick = SystematicResample(w, 100, u);
    ASSERT_EQ(pick.size(), 100u);
    std::vector<int> count(4, 0);
    for (size_t i : pick) ++count[i];
    EXPECT_NEAR(count[0], 10, 1);
    EXPECT_EQ(count[1], 0);  // a zero weight is never drawn
    EXPECT_NEAR(count[2], 60, 1);
    EXPECT_NEAR(count[3], 30, 1);
    for (size_t k = 1; k < pick.size(); ++k) EXPECT_GE(pick[k], pick[k - 1]);
  }
  EXPECT_TRUE(SystematicResample({0.0, 0.0}, 10, 0.5).empty());
}

TEST(WeightedKMeansTest, FindsPlantedClusters) {
  Random random(5);
  const std::vector<Point2> truth = {{0, 0}, {20, 0}, {0, 30}, {25, 25}};
  std::vector<Point2> points;
  std::vector<double> weights;
  for (size_t c = 0; c < truth.size(); ++c) {
    for (int i = 0; i < 200; ++i) {
      points.push_back({truth[c].x + random.Gaussian(0, 1), truth[c].y + random.Gaussian(0, 1)});
      weights.push_back(c == 0 ? 2.0 : 1.0);  // the first cluster carries twice the weight
    }
  }
  Random seeded(9);
  const auto centres = WeightedKMeans(points, weights, 4, &seeded);
  ASSERT_EQ(centres.size(), 4u);
  std::set<size_t> found;
  for (const auto& [c, share] : centres) {
    for (size_t t = 0; t < truth.size(); ++t) {
      if (std::hypot(c.x - truth[t].x, c.y - truth[t].y) < 0.5) found.insert(t);
    }
  }
  EXPECT_EQ(found.size(), 4u);
  // Heaviest first: the doubled cluster holds 2/5 of the weight.
  EXPECT_NEAR(centres[0].second, 0.4, 1e-9);
  EXPECT_NEAR(centres[0].first.x, 0.0, 0.5);
  // Fewer distinct points than k: fewer centres, no crash.
  Random again(1);
  EXPECT_EQ(WeightedKMeans({{1, 1}, {1, 1}}, {1, 1}, 12, &again).size(), 1u);
  EXPECT_TRUE(WeightedKMeans({}, {}, 12, &again).empty());
}

// A 40 m x 20 m floor with APs on a grid and log-distance path loss: the map is trained on
// noise-free samples every metre, and a phone walking a known path with noisy scans and steps.
struct Field {
  std::vector<Point2> aps;
  Field() {
    for (double x = 0; x <= 40; x += 10) {
      for (double y = 0; y <= 20; y += 10) aps.push_back({x, y});
    }
  }
  std::vector<std::pair<std::string, double>> Scan(const Point2& p, Random* noise) const {
    std::vector<std::pair<std::string, double>> r;
    for (size_t a = 0; a < aps.size(); ++a) {
      const double d = std::hypot(p.x - aps[a].x, p.y - aps[a].y);
      const double rssi = -30.0 - 25.0 * std::log10(1.0 + d) + (noise ? noise->Gaussian(0, 3) : 0);
      if (rssi > -85.0) r.emplace_back("ap" + std::to_string(a), rssi);
    }
    return r;
  }
};

// Noise-free samples of the field every 2 m along x and 4 m along y.
std::vector<WifiMapSample> FieldSamples(const Field& field) {
  std::vector<WifiMapSample> samples;
  for (double x = 0; x <= 40; x += 2.0) {
    for (double y = 0; y <= 20; y += 4.0)
      samples.push_back({{x, y}, 0, field.Scan({x, y}, nullptr)});
  }
  return samples;
}

WifiGpMap TrainedMap(const Field& field) {
  const std::vector<WifiMapSample> samples = FieldSamples(field);
  WifiGpOptions options;
  options.length_scale_m = 3.0;
  StatusOr<WifiGpMap> map = WifiGpMap::Build(samples, options);
  EXPECT_TRUE(map.ok()) << map.status().message();
  return std::move(map.value());
}

// A cell far too small for the area is refused before anything is allocated, naming the key and
// what it would take (1 cm cells, 12 m margins, 15 APs over this 40 m x 20 m floor: 4e8 cells).
TEST(WifiGpMapTest, AGridThatWouldNotFitInMemoryIsRefusedUpFront) {
  WifiGpOptions options;
  options.cell_size_m = 0.01;
  options.grid_margin_m = 12;
  const StatusOr<WifiGpMap> map = WifiGpMap::Build(FieldSamples(Field()), options);
  ASSERT_FALSE(map.ok());
  EXPECT_NE(map.status().message().find("[wifi_map] cell_size_m = 0.01 m would need up to"),
            std::string::npos)
      << map.status().message();
}

TEST(WifiGpMapTest, PredictsTheFieldNearItsSamplesAndThePriorElsewhere) {
  const Field field;
  const WifiGpMap map = TrainedMap(field);
  EXPECT_EQ(map.bssids().size(), field.aps.size());
  EXPECT_EQ(map.floors(), std::vector<int>{0});
  // Between the samples the mean is within a few dB of the truth where the AP is heard well.
  std::vector<double> errors;
  for (double x = 3.5; x <= 36; x += 3.7) {
    for (double y = 3.1; y <= 17; y += 3.3) {
      for (const auto& [bssid, rssi] : field.Scan({x, y}, nullptr)) {
        if (rssi < -70) continue;  // near the edge of hearing the unheard floor pulls it down
        bool stored = false;
        const auto c = map.Predict(static_cast<size_t>(map.Find(bssid)), 0, {x, y}, &stored);
        ASSERT_TRUE(stored);
        errors.push_back(std::abs(c.mean_dbm - rssi));
      }
    }
  }
  // Samples 2-4 m apart miss the sharp peak next to an AP; elsewhere the GP is close.
  ASSERT_GT(errors.size(), 100u);
  std::sort(errors.begin(), errors.end());
  double sum = 0.0;
  for (double e : errors) sum += e;
  EXPECT_LT(sum / errors.size(), 1.5);
  EXPECT_LT(errors[errors.size() * 9 / 10], 3.0);
  // Far off the floor and on another floor: the prior.
  bool stored = true;
  const auto far = map.Predict(0, 0, {500, 500}, &stored);
  EXPECT_FALSE(stored);
  EXPECT_EQ(far.mean_dbm, -100.0f);
  EXPECT_FALSE(map.Covers(3, {10, 10}));
  EXPECT_TRUE(map.Covers(0, {10, 10}));
  EXPECT_EQ(map.Find("nope"), -1);
}

TEST(WifiGpMapTest, MarginalLikelihoodFindsTheMeasurementNoise) {
  // The field's readings carry 3 dBm of Gaussian noise; start the fit from 12 dBm.
  const Field field;
  Random noise(21);
  std::vector<WifiMapSample> samples;
  for (double x = 0; x <= 40; x += 2.0) {
    for (double y = 0; y <= 20; y += 2.0)
      samples.push_back({{x, y}, 0, field.Scan({x, y}, &noise)});
  }
  WifiGpOptions options;
  options.length_scale_m = 3.0;
  options.noise_sigma_dbm = 12.0;
  options.fit_hyperparameters = true;
  StatusOr<WifiGpMap> map = WifiGpMap::Build(samples, options);
  ASSERT_TRUE(map.ok()) << map.status().message();
  ASSERT_TRUE(map->fit_report().has_value());
  EXPECT_GT(map->fit_report()->log_likelihood_after, map->fit_report()->log_likelihood_before);
  EXPECT_GE(map->options().noise_sigma_dbm, 2.0);
  EXPECT_LE(map->options().noise_sigma_dbm, 5.0);
  EXPECT_EQ(map->options().length_scale_m, 3.0);  // not asked to fit it
  // The fitted values are what the file keeps.
  StatusOr<WifiGpMap> back = WifiGpMap::Decode(map->Encode(), "f.wifimap");
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->options().noise_sigma_dbm, map->options().noise_sigma_dbm);
  // Without the flag nothing is fitted.
  options.fit_hyperparameters = false;
  StatusOr<WifiGpMap> plain = WifiGpMap::Build(samples, options);
  ASSERT_TRUE(plain.ok());
  EXPECT_FALSE(plain->fit_report().has_value());
  EXPECT_EQ(plain->options().noise_sigma_dbm, 12.0);
}

TEST(WifiGpMapTest, FileRoundTripAndBadFiles) {
  const WifiGpMap map = TrainedMap(Field());
  const std::string bytes = map.Encode();
  StatusOr<WifiGpMap> back = WifiGpMap::Decode(bytes, "w.wifimap");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->bssids(), map.bssids());
  EXPECT_EQ(back->stored_cells(), map.stored_cells());
  EXPECT_EQ(back->Predict(3, 0, {12.3, 4.5}).mean_dbm, map.Predict(3, 0, {12.3, 4.5}).mean_dbm);
  for (size_t cut : {size_t{0}, size_t{5}, bytes.size() / 2, bytes.size() - 1}) {
    StatusOr<WifiGpMap> bad = WifiGpMap::Decode(bytes.substr(0, cut), "w.wifimap");
    ASSERT_FALSE(bad.ok()) << "cut at " << cut;
    EXPECT_NE(bad.status().message().find("w.wifimap"), std::string::npos);
  }
  EXPECT_FALSE(WifiGpMap::Decode(bytes + "x", "w.wifimap").ok());
  // Bad input to Build: no sample, a NaN position, a NaN reading.
  EXPECT_FALSE(WifiGpMap::Build({}, WifiGpOptions()).ok());
  EXPECT_FALSE(WifiGpMap::Build({{{NAN, 0}, 0, {{"a", -50}}}}, WifiGpOptions()).ok());
  EXPECT_FALSE(WifiGpMap::Build({{{0, 0}, 0, {{"a", NAN}}}}, WifiGpOptions()).ok());
}

TEST(WifiGpMapTest, EverySingleByteChangeIsAnError) {
  const std::string bytes = TrainedMap(Field()).Encode();
  for (size_t i = 0; i < bytes.size(); i += 1 + i / 32) {
    std::string flipped = bytes;
    flipped[i] = static_cast<char>(flipped[i] ^ 0x21);
    EXPECT_FALSE(WifiGpMap::Decode(flipped, "w.wifimap").ok()) << "byte " << i;
  }
  std::string flipped = bytes;
  flipped[bytes.size() / 2] ^= 1;
  const StatusOr<WifiGpMap> bad = WifiGpMap::Decode(flipped, "w.wifimap");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("w.wifimap: checksum mismatch"), std::string::npos)
      << bad.status().message();
}

TEST(WifiGpMapTest, RunFrameRoundTripsAndFormatsOneAndTwoStillRead) {
  WifiGpMap map = TrainedMap(Field());
  // Formats 1 and 2 had no checksum: the bodies below are format 3's without its trailer.
  const std::string checked = map.Encode();
  const std::string plain = checked.substr(0, checked.size() - 4);
  map.set_compass_to_map_rad(1.1);  // its lowest byte differs from 0.0's
  RigidAlignment2D a;
  a.rotation_rad = -0.5;
  a.translation_x_m = 3.0;
  a.translation_y_m = -4.0;
  a.rmse_m = 1.5;
  map.set_truth_from_map(a);
  const std::string framed_checked = map.Encode();
  const std::string framed = framed_checked.substr(0, framed_checked.size() - 4);
  StatusOr<WifiGpMap> back = WifiGpMap::Decode(framed_checked, "w.wifimap");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->compass_to_map_rad(), 1.1);
  ASSERT_TRUE(back->truth_from_map().has_value());
  EXPECT_EQ(back->truth_from_map()->rotation_rad, -0.5);
  EXPECT_EQ(back->truth_from_map()->translation_y_m, -4.0);
  EXPECT_EQ(back->truth_from_map()->rmse_m, 1.5);
  // Walls round-trip too.
  WifiGpMap walled = map;
  walled.set_walls({{1, {0, 0}, {3, 4}}, {-2, {1.5, -1}, {1.5, 9}}});
  StatusOr<WifiGpMap> w = WifiGpMap::Decode(walled.Encode(), "w.wifimap");
  ASSERT_TRUE(w.ok()) << w.status().message();
  ASSERT_EQ(w->walls().size(), 2u);
  EXPECT_EQ(w->walls()[1].floor, -2);
  EXPECT_EQ(w->walls()[1].b.y, 9.0);
  EXPECT_EQ(w->walls()[0].a.x, 0.0);
  // A format-1 file is the format-2 one without the two option flags format 2 added (bytes
  // 85-86: after the 20-byte magic and version, eight doubles and one flag) and without the
  // frame block (a double, a flag, four doubles and a wall count: 49 bytes), with version 1: it
  // reads with no frame.
  ASSERT_EQ(plain.size(), framed.size());
  size_t first = 0;
  while (plain[first] == framed[first]) ++first;
  const size_t version_at = plain.find("RSWIFIGP") + 8;
  uint32_t version = 0;
  std::memcpy(&version, plain.data() + version_at, 4);
  ASSERT_EQ(version, 3u);
  // Format 2 is format 3's body under version 2.
  std::string v2 = plain;
  version = 2;
  std::memcpy(v2.data() + version_at, &version, 4);
  StatusOr<WifiGpMap> two = WifiGpMap::Decode(v2, "v2.wifimap");
  ASSERT_TRUE(two.ok()) << two.status().message();
  EXPECT_EQ(two->stored_cells(), map.stored_cells());
  ASSERT_EQ(plain[85], 0);  // fit_hyperparameters false
  ASSERT_EQ(plain[86], 0);  // fit_length_scale false
  ASSERT_GT(first, 87u);
  std::string v1 = plain.substr(0, 85) + plain.substr(87, first - 87) + plain.substr(first + 49);
  version = 1;
  std::memcpy(v1.data() + version_at, &version, 4);
  StatusOr<WifiGpMap> old = WifiGpMap::Decode(v1, "v1.wifimap");
  ASSERT_TRUE(old.ok()) << old.status().message();
  EXPECT_EQ(old->compass_to_map_rad(), 0.0);
  EXPECT_FALSE(old->truth_from_map().has_value());
  EXPECT_EQ(old->stored_cells(), map.stored_cells());
  EXPECT_EQ(old->options().grid_margin_m, map.options().grid_margin_m);
  EXPECT_EQ(old->options().signal_dependent_variance, map.options().signal_dependent_variance);
  EXPECT_EQ(old->Predict(3, 0, {12.3, 4.5}).mean_dbm, map.Predict(3, 0, {12.3, 4.5}).mean_dbm);
  // A frame out of range is refused.
  map.set_compass_to_map_rad(1e9);
  EXPECT_FALSE(WifiGpMap::Decode(map.Encode(), "w.wifimap").ok());
}

TEST(SegmentsIntersectTest, KnownCases) {
  EXPECT_TRUE(SegmentsIntersect({0, 0}, {2, 2}, {0, 2}, {2, 0}));      // an X
  EXPECT_FALSE(SegmentsIntersect({0, 0}, {1, 0}, {0, 1}, {1, 1}));     // parallel
  EXPECT_TRUE(SegmentsIntersect({0, 0}, {1, 0}, {1, -1}, {1, 1}));     // touching an end
  EXPECT_FALSE(SegmentsIntersect({0, 0}, {1, 0}, {2, 0}, {3, 0}));     // collinear, apart
  EXPECT_TRUE(SegmentsIntersect({0, 0}, {2, 0}, {1, 0}, {3, 0}));      // collinear, overlapping
  EXPECT_FALSE(SegmentsIntersect({0, 0}, {0.9, 0}, {1, -1}, {1, 1}));  // stops short
}

TEST(ParticleFilterTest, AParticleThatWalksThroughAWallDies) {
  // A wall across the whole field at x = 10 (and one on another floor, which must not count).
  WifiGpMap map = TrainedMap(Field());
  map.set_walls({{0, {10, -100}, {10, 100}}, {5, {12, -100}, {12, 100}}});
  ParticleFilterOptions options;
  options.particles = 3000;
  options.step_length_sigma = 0.0;
  options.heading_sigma_rad = 0.0;
  options.heading_offset_walk_rad = 0.0;
  options.compass_offset_sigma_rad = 0.0;
  ParticleFilter filter(map, options);
  ASSERT_TRUE(filter.Initialise(true).ok());
  const std::vector<Particle> before = filter.particles();
  filter.Step(1.5, 0.0);  // 1.5 m east
  const std::vector<Particle>& after = filter.particles();
  size_t crossed = 0;
  for (size_t i = 0; i < after.size(); ++i) {
    ASSERT_NEAR(after[i].x_m - before[i].x_m, 1.5, 1e-12);
    const bool through = before[i].x_m <= 10.0 && after[i].x_m >= 10.0;
    crossed += through;
    if (through) {
      EXPECT_EQ(after[i].weight, 0.0) << "particle " << i << " walked through the wall";
    } else {
      EXPECT_GT(after[i].weight, 0.0);
    }
  }
  EXPECT_GT(crossed, 0u);
  EXPECT_EQ(filter.wall_crossings(), crossed);
}

TEST(ParticleFilterTest, ConvergesOnTheWalkerInAKnownField) {
  const Field field;
  const WifiGpMap map = TrainedMap(field);
  for (const auto& [likelihood, reseed] :
       {std::pair{ScanLikelihood::kSum, 0.0}, std::pair{ScanLikelihood::kProduct, 0.0},
        std::pair{ScanLikelihood::kSum, 0.05}, std::pair{ScanLikelihood::kProduct, 0.05}}) {
    ParticleFilterOptions options;
    options.likelihood = likelihood;
    options.particles = 3000;
    options.reseed_fraction = reseed;
    options.first_reseed_fraction = reseed == 0.0 ? 0.0 : 0.5;
    ParticleFilter filter(map, options);
    ASSERT_TRUE(filter.Initialise(/*have_compass=*/true).ok());
    Random noise(7);
    // Walk east along y = 10 at 1 m per step, a scan every 2 steps.
    Point2 at{3, 10};
    std::vector<double> errors;
    for (int step = 1; step <= 34; ++step) {
      at.x += 1.0;
      filter.Step(1.0 + noise.Gaussian(0, 0.05), noise.Gaussian(0, 0.03));
      if (step % 2) continue;
      EXPECT_GT(filter.Update(field.Scan(at, &noise)), 0u);
      const LocationEstimate e = filter.Estimate();
      errors.push_back(std::hypot(e.x_m - at.x, e.y_m - at.y));
    }
    // Chance: a uniform guess on the 40 x 20 m floor is about 12 m from the walker on average.
    double late = 0.0;
    for (size_t i = errors.size() - 5; i < errors.size(); ++i) late += errors[i] / 5;
    EXPECT_LT(late, 2.5) << ToString(likelihood) << " reseed " << reseed;
    // From the uniform start the weights must concentrate (with resetting they may not need to).
    if (reseed == 0.0) {
      EXPECT_GT(filter.resamplings(), 0u);
    }
    const auto candidates = filter.Candidates();
    ASSERT_FALSE(candidates.empty());
    EXPECT_LE(candidates.size(), 12u);
    EXPECT_LT(std::hypot(candidates[0].first.x - at.x, candidates[0].first.y - at.y), 3.0);
  }
}

// A second phone that reads 10 dB lower than the one that made the map: without the offset it
// looks farther from every AP than it is. With online_rssi_offset the filter estimates the offset
// from the scans alone (no position) and, once it is removed, locates the walker as well as the
// map's own phone does (the bound of ConvergesOnTheWalkerInAKnownField).
TEST(ParticleFilterTest, OnlineRssiOffsetRecoversAPlantedOffset) {
  const Field field;
  const WifiGpMap map = TrainedMap(field);
  constexpr double kOffsetDb = -10.0;
  for (ScanLikelihood likelihood : {ScanLikelihood::kSum, ScanLikelihood::kProduct}) {
    std::map<bool, double> late_error;
    for (bool online : {false, true}) {
      ParticleFilterOptions options;
      options.likelihood = likelihood;
      options.particles = 3000;
      options.online_rssi_offset = online;
      ParticleFilter filter(map, options);
      ASSERT_TRUE(filter.Initialise(/*have_compass=*/true).ok());
      Random noise(7);
      // East along y = 10 and back, a scan every 2 steps.
      Point2 at{3, 10};
      std::vector<double> errors;
      for (int step = 1; step <= 68; ++step) {
        const double dx = step <= 34 ? 1.0 : -1.0;
        at.x += dx;
        filter.Step(1.0 + noise.Gaussian(0, 0.05),
                    (step <= 34 ? 0.0 : std::numbers::pi) + noise.Gaussian(0, 0.03));
        if (step % 2) continue;
        auto scan = field.Scan(at, &noise);
        for (auto& reading : scan) reading.second += kOffsetDb;
        EXPECT_GT(filter.Update(scan), 0u);
        const LocationEstimate e = filter.Estimate();
        errors.push_back(std::hypot(e.x_m - at.x, e.y_m - at.y));
      }
      double late = 0.0;
      for (size_t i = errors.size() - 10; i < errors.size(); ++i) late += errors[i] / 10;
      late_error[online] = late;
      if (online) {
        // Readings carry 3 dB of noise each; the median of per-scan medians is much closer.
        EXPECT_NEAR(filter.rssi_offset_db(), kOffsetDb, 1.0) << ToString(likelihood);
      } else {
        EXPECT_EQ(filter.rssi_offset_db(), 0.0);
      }
    }
    // Measured: sum 5.1 m without, 0.6 m with; product 10.2 m and 1.0 m.
    EXPECT_LT(late_error[true], 2.5) << ToString(likelihood);
    EXPECT_GT(late_error[false], 2.0 * late_error[true]) << ToString(likelihood);
  }
}

// The kidnapped phone: after the filter has converged on a walker at the west end, the walker is
// carried 30 m east without a step. With sensor resetting the filter finds it again within five
// scans; without it (reseed fractions 0) the particles, all in the west, only diffuse towards
// it (measured: still 20 m off after five scans, 4 m after fifteen).
TEST(ParticleFilterTest, SensorResettingFindsAKidnappedPhone) {
  const Field field;
  const WifiGpMap map = TrainedMap(field);
  auto late_error = [&](double reseed) {
    ParticleFilterOptions options;
    options.particles = 2000;
    options.likelihood = ScanLikelihood::kProduct;  // collapses quickly onto the walker
    options.reseed_fraction = reseed;
    options.first_reseed_fraction = reseed;
    ParticleFilter filter(map, options);
    EXPECT_TRUE(filter.Initialise(true).ok());
    Random noise(3);
    Point2 at{4, 10};
    for (int scan = 0; scan < 12; ++scan) filter.Update(field.Scan(at, &noise));
    const LocationEstimate before = filter.Estimate();
    EXPECT_LT(std::hypot(before.x_m - at.x, before.y_m - at.y), 2.5) << "reseed " << reseed;
    at = {34, 10};  // kidnapped
    double error = 0.0;
    for (int scan = 0; scan < 5; ++scan) {
      filter.Diffuse(1.0);
      filter.Update(field.Scan(at, &noise));
      const LocationEstimate e = filter.Estimate();
      error = std::hypot(e.x_m - at.x, e.y_m - at.y);
    }
    return error;
  };
  EXPECT_LT(late_error(0.05), 2.5);
  EXPECT_GT(late_error(0.0), 10.0);
}

TEST(ParticleFilterTest, UnknownApsAndAnEmptyMapLeaveABeliefNotACrash) {
  const WifiGpMap map = TrainedMap(Field());
  ParticleFilter filter(map, ParticleFilterOptions());
  ASSERT_TRUE(filter.Initialise(false).ok());
  const double ess = filter.EffectiveSampleSize();
  EXPECT_EQ(filter.Update({{"unknown", -60.0}}), 0u);  // weights unchanged
  EXPECT_DOUBLE_EQ(filter.EffectiveSampleSize(), ess);
  EXPECT_EQ(filter.Update({}), 0u);
  filter.Diffuse(2.0);
  StatusOr<WifiGpMap> nothing = WifiGpMap::Build({{{0, 0}, 0, {}}}, WifiGpOptions());
  ASSERT_TRUE(nothing.ok());
  ParticleFilter empty(*nothing, ParticleFilterOptions());
  EXPECT_FALSE(empty.Initialise(false).ok());
}

}  // namespace
}  // namespace ratslam::phone
