#include "sensors/barometer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "common/byte_buffer.h"

namespace ratslam::sensors {
namespace {

// A 10 Hz pressure trace through heights given as (duration s, height m at its end) legs,
// linear within each leg, with Gaussian sensor noise and a weather drift in hPa per hour. The
// pressure of a height follows the barometric formula of the standard atmosphere (an oracle
// independent of the tracker's logarithmic scale height).
struct Trace {
  std::vector<PressureSample> samples;
  std::vector<double> true_height_m;
};
Trace MakeTrace(const std::vector<std::pair<double, double>>& legs, double noise_hpa,
                double drift_hpa_per_hour, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_hpa);
  Trace trace;
  double t = 0.0, h = 0.0;
  for (const auto& [duration, end] : legs) {
    const double start = h;
    for (double s = 0.0; s < duration; s += 0.1, t += 0.1) {
      h = start + (end - start) * s / duration;
      const double p = 1013.25 * std::pow(1.0 - 2.25577e-5 * (30.0 + h), 5.25588);
      trace.samples.push_back({t, p + drift_hpa_per_hour * t / 3600.0 + noise(rng)});
      trace.true_height_m.push_back(h);
    }
    h = end;
  }
  return trace;
}

TEST(BarometerTest, StairClimbsGiveTheRightFloorsAndLandingsAreNotFloors) {
  // Floor 0 for 30 s; up a flight with a 5 s half landing to 3.5 m; 30 s there; up to 7 m; 30 s;
  // straight down two floors in 25 s; 30 s; back up one floor; 30 s.
  const Trace trace = MakeTrace({{30, 0.0},
                                 {6, 1.75},
                                 {5, 1.75},
                                 {6, 3.5},
                                 {30, 3.5},
                                 {12, 7.0},
                                 {30, 7.0},
                                 {25, 0.0},
                                 {30, 0.0},
                                 {12, 3.5},
                                 {30, 3.5}},
                                0.03, 0.5, 1);
  BarometricFloorTracker tracker;
  std::vector<int> floors;
  for (const PressureSample& s : trace.samples) {
    StatusOr<FloorEstimate> e = tracker.Add(s);
    ASSERT_TRUE(e.ok()) << e.status().message();
    floors.push_back(e->floor);
  }
  auto floor_at = [&](double t) { return floors[static_cast<size_t>(t * 10)]; };
  EXPECT_EQ(floor_at(29), 0);
  EXPECT_EQ(floor_at(45), 0);  // the half landing (41 s to 46 s) is no floor
  EXPECT_EQ(floor_at(76), 1);  // end of the 30 s on the first floor
  EXPECT_EQ(floor_at(117), 2);
  EXPECT_EQ(floor_at(171), 0);  // two floors down in one go
  EXPECT_EQ(floor_at(215), 1);  // a revisit of the first floor
  EXPECT_EQ(tracker.levels(), 3u);
  // 0 -> 1 -> 2 -> (passing 1) -> 0 -> 1: the descent passes the first floor's known height.
  EXPECT_EQ(tracker.floor_changes(), 5u);
  EXPECT_NEAR(tracker.storey_m(), 3.5, 0.3);
  // Once the truth has stayed at one height for a dwell (8 s) and a second, the estimate is
  // right: floor = height / 3.5 m at every such reading. Before that it lags by design.
  size_t settled = 0, agree = 0;
  for (size_t i = 90; i < floors.size(); ++i) {
    bool still = true;
    for (size_t k = i - 90; k < i && still; ++k) {
      still = trace.true_height_m[k] == trace.true_height_m[i];
    }
    if (!still) continue;
    ++settled;
    agree += floors[i] == std::lround(trace.true_height_m[i] / 3.5);
  }
  EXPECT_GT(settled, floors.size() / 3);
  EXPECT_EQ(agree, settled);
}

TEST(BarometerTest, AnHourOnOneFloorWithWeatherDriftAndARampIsOneFloor) {
  // 2 hPa per hour of weather is about 17 m of apparent climb over the hour; pauses every few
  // minutes re-measure the level. A 1 m ramp up and back is no floor either.
  std::vector<std::pair<double, double>> legs;
  for (int i = 0; i < 30; ++i) {
    legs.push_back({100, 0.0});
    legs.push_back({10, i % 5 == 0 ? 1.0 : 0.0});
    legs.push_back({10, 0.0});
  }
  const Trace trace = MakeTrace(legs, 0.03, 2.0, 2);
  StatusOr<std::vector<FloorEstimate>> estimates = EstimateFloors(trace.samples);
  ASSERT_TRUE(estimates.ok()) << estimates.status().message();
  for (const FloorEstimate& e : *estimates) ASSERT_EQ(e.floor, 0) << e.time_s;
}

TEST(BarometerTest, TransitIsFlaggedBetweenFloors) {
  const Trace trace = MakeTrace({{20, 0.0}, {20, 4.0}, {20, 4.0}}, 0.0, 0.0, 3);
  StatusOr<std::vector<FloorEstimate>> estimates = EstimateFloors(trace.samples);
  ASSERT_TRUE(estimates.ok());
  EXPECT_FALSE((*estimates)[150].in_transit);  // 15 s: dwelling on floor 0
  EXPECT_TRUE((*estimates)[350].in_transit);   // 35 s: half way up
  EXPECT_FALSE((*estimates)[590].in_transit);  // 59 s: settled on the next floor
  EXPECT_EQ((*estimates)[590].floor, 1);
}

TEST(BarometerTest, BadReadingsAreErrorsNamingTheReading) {
  auto error = [](std::vector<PressureSample> samples) {
    StatusOr<std::vector<FloorEstimate>> e = EstimateFloors(samples);
    return e.ok() ? std::string() : e.status().message();
  };
  EXPECT_NE(error({{1.0, 1000.0}, {0.5, 1000.0}}).find("reading 2"), std::string::npos);
  EXPECT_NE(error({{1.0, 1000.0}, {0.5, 1000.0}}).find("backwards"), std::string::npos);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(error({{nan, 1000.0}}).find("reading 1"), std::string::npos);
  EXPECT_NE(error({{0.0, nan}}).find("pressure"), std::string::npos);
  EXPECT_NE(error({{0.0, 0.0}}).find("outside"), std::string::npos);
  BarometerOptions bad;
  bad.min_floor_change_m = 0.5;  // below the dwell band
  StatusOr<std::vector<FloorEstimate>> e = EstimateFloors({{0.0, 1000.0}}, bad);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.status().message().find("min_floor_change_m"), std::string::npos);
}

// A tracker saved halfway through a climb and restored goes on exactly as one never stopped, and
// bytes it did not write (cut short, or a level index past its levels) are refused.
TEST(BarometerTest, StateRoundTripsAndCorruptStatesAreRefused) {
  const Trace trace =
      MakeTrace({{20, 0.0}, {10, 3.5}, {20, 3.5}, {10, 0.0}, {20, 0.0}}, 0.03, 0.5, 4);
  BarometricFloorTracker whole, first;
  const size_t half = 280;  // on the way up
  std::string bytes;
  for (size_t i = 0; i < trace.samples.size(); ++i) {
    const FloorEstimate a = whole.Add(trace.samples[i]).value();
    if (i < half) {
      first.Add(trace.samples[i]).value();
      continue;
    }
    if (i == half) {
      ByteWriter w;
      first.Encode(&w);
      bytes = w.bytes();
    }
    BarometricFloorTracker restored;
    ByteReader r(bytes, "barometer state");
    ASSERT_TRUE(restored.Decode(&r)) << r.error();
    ASSERT_TRUE(r.AtEnd());
    const FloorEstimate b = restored.Add(trace.samples[i]).value();
    EXPECT_EQ(a.floor, b.floor);
    EXPECT_EQ(a.level, b.level);
    EXPECT_EQ(a.in_transit, b.in_transit);
    EXPECT_EQ(a.height_m, b.height_m);
    ByteWriter w;
    restored.Encode(&w);
    bytes = w.bytes();
  }
  EXPECT_EQ(whole.floor_changes(), 2u);
  for (size_t cut = 1; cut < bytes.size(); cut += 7) {
    BarometricFloorTracker t;
    ByteReader r(std::string_view(bytes).substr(0, bytes.size() - cut), "barometer state");
    EXPECT_FALSE(t.Decode(&r) && r.AtEnd()) << cut;
  }
  // The current level (an int32 just before the storey height, last time and change count)
  // pointing past the levels.
  std::string wrong = bytes;
  const size_t current_at = wrong.size() - 8 - 8 - 8 - 4;
  const int32_t past = 99;
  std::memcpy(&wrong[current_at], &past, sizeof(past));
  BarometricFloorTracker t;
  ByteReader r(wrong, "barometer state");
  EXPECT_FALSE(t.Decode(&r));
  EXPECT_NE(r.error().find("does not fit"), std::string::npos) << r.error();
}

}  // namespace
}  // namespace ratslam::sensors
