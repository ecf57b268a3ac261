#include "fusion/front_end.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <tuple>

#include "common/random.h"

namespace ratslam::fusion {
namespace {

// A 24x18 grey image with a distinct pattern per seed.
GrayImage Pattern(int seed) {
  GrayImage image{24, 18, std::vector<uint8_t>(24 * 18)};
  for (int y = 0; y < 18; ++y)
    for (int x = 0; x < 24; ++x)
      image.pixels[y * 24 + x] =
          static_cast<uint8_t>((x * (7 + seed * 13) + y * (3 + seed * 5)) % 256);
  return image;
}

WifiScan Scan(double t, int seed) {
  WifiScan s{t, {}};
  for (int i = 0; i < 6; ++i)
    s.readings.push_back({"ap" + std::to_string(seed * 10 + i), -50.0 - i});
  return s;
}

class BOutRuleTest : public ::testing::Test {
 protected:
  void SetUp() override {
    settings_.front_end.kind = FrontEndKind::kFused;
    settings_.fused.use_camera = true;
    settings_.fused.use_wifi = true;
    settings_.fused.use_compass = true;
    settings_.fused.recency_s = 40.0;
    settings_.fused.max_wifi_age_s = 5.0;
    front_end_ = CreateFrontEnd(settings_);
  }
  // A frame: the scan arrives just before the image.
  FrameDecision Frame(double t, int image, std::optional<int> scan, double heading = 0.0) {
    front_end_->OnCompass(t, heading);
    if (scan) {
      EXPECT_FALSE(front_end_->OnWifi(Scan(t - 0.5, *scan)).value().has_value());
    }
    auto d = front_end_->OnImage(t, Pattern(image));
    EXPECT_TRUE(d.ok());
    return d.value().value();
  }
  FrontEndSettings settings_;
  std::unique_ptr<FrontEnd> front_end_;
};

TEST_F(BOutRuleTest, TruthTable) {
  // Both novel: a new joint template each time.
  FrameDecision d = Frame(0, 1, 1);
  EXPECT_TRUE(d.view.is_new);
  EXPECT_EQ(d.view.template_id, 0u);
  d = Frame(100, 2, 2);
  EXPECT_TRUE(d.view.is_new);
  EXPECT_EQ(d.view.template_id, 1u);
  // Camera matches template 0 while Wi-Fi matches template 1: the camera is preferred.
  d = Frame(200, 1, 2);
  EXPECT_FALSE(d.view.is_new);
  EXPECT_EQ(d.view.template_id, 0u);
  EXPECT_EQ(d.source, DecisionSource::kCamera);
  EXPECT_FALSE(d.recent);
  // Camera novel, Wi-Fi matches template 0: Wi-Fi decides.
  d = Frame(300, 3, 1);
  EXPECT_FALSE(d.view.is_new);
  EXPECT_EQ(d.view.template_id, 0u);
  EXPECT_EQ(d.source, DecisionSource::kWifi);
  // Both novel again: new template 2.
  d = Frame(400, 4, 4);
  EXPECT_TRUE(d.view.is_new);
  EXPECT_EQ(d.view.template_id, 2u);
  EXPECT_EQ(front_end_->size(), 3u);
}

TEST_F(BOutRuleTest, RecentMatchIsReusedWithoutInjection) {
  Frame(0, 1, 1);
  const FrameDecision d = Frame(10, 1, 1);  // template 0 is only 10 s old (k = 40 s)
  EXPECT_FALSE(d.view.is_new);
  EXPECT_EQ(d.view.template_id, 0u);
  EXPECT_TRUE(d.recent);
  EXPECT_FALSE(d.view.allow_injection);
  EXPECT_EQ(front_end_->size(), 1u);
}

TEST_F(BOutRuleTest, StaleScanCountsAsAbsent) {
  Frame(0, 1, 1);
  // Wi-Fi would match template 0, but the newest scan is 20 s old at this frame.
  EXPECT_FALSE(front_end_->OnWifi(Scan(80, 1)).value().has_value());
  auto d = front_end_->OnImage(100, Pattern(5));
  ASSERT_TRUE(d.ok());
  EXPECT_TRUE(d.value()->view.is_new);
}

TEST_F(BOutRuleTest, CompassGivesHeadingChange) {
  Frame(0, 1, 1, /*heading=*/0.3);
  const FrameDecision d = Frame(100, 6, 1, /*heading=*/0.3 + M_PI / 2);  // Wi-Fi match, turned left
  EXPECT_EQ(d.source, DecisionSource::kWifi);
  EXPECT_NEAR(d.view.heading_change_rad, M_PI / 2, 1e-12);  // eq. 2 with the sign of a change
}

TEST(FrontEndTest, WifiOnlyMakesFramesFromScansAndStateRoundTrips) {
  FrontEndSettings settings;
  settings.front_end.kind = FrontEndKind::kFused;
  settings.fused.use_camera = false;
  settings.fused.recency_s = 0.0;
  std::unique_ptr<FrontEnd> a = CreateFrontEnd(settings);
  EXPECT_FALSE(a->WantsImages());
  ASSERT_TRUE(a->OnWifi(Scan(0, 1)).value().has_value());
  ASSERT_TRUE(a->OnWifi(Scan(1, 2)).value().has_value());
  std::unique_ptr<FrontEnd> b = CreateFrontEnd(settings);
  ASSERT_TRUE(b->DecodeState(a->EncodeState()).ok());
  EXPECT_EQ(b->size(), 2u);
  const auto da = a->OnWifi(Scan(5, 1)).value();
  const auto db = b->OnWifi(Scan(5, 1)).value();
  EXPECT_EQ(da->view.template_id, db->view.template_id);
  EXPECT_EQ(da->source, DecisionSource::kWifi);
  std::string corrupt = a->EncodeState();
  corrupt.resize(corrupt.size() / 2);
  EXPECT_FALSE(b->DecodeState(corrupt).ok());
}

// Each front end names the stream it lacks, and the suggested config fits what the data has.
TEST(FrontEndTest, MissingInputStreamsAreNamedWithAConfigThatFits) {
  dataset::Dataset phone;  // an IPIN log: scans and headings, no images
  phone.name = "phone";
  phone.wifi.push_back({1.0, {{"ap", -50.0}}});
  phone.compass.push_back({1.0, 0.0});
  FrontEndSettings classic;  // the default: classic camera
  Status s = CheckFrontEndInputs(classic, phone);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("classic_camera front end needs camera images"), std::string::npos)
      << s.message();
  EXPECT_NE(s.message().find("configs/ipin2023-wifi-compass.toml"), std::string::npos);

  FrontEndSettings wifi_compass;
  wifi_compass.front_end.kind = FrontEndKind::kFused;
  wifi_compass.fused.use_compass = true;
  EXPECT_TRUE(CheckFrontEndInputs(wifi_compass, phone).ok());
  dataset::Dataset no_compass = phone;
  no_compass.compass.clear();
  s = CheckFrontEndInputs(wifi_compass, no_compass);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("a compass (heading) stream"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("configs/ipin2023-wifi.toml"), std::string::npos) << s.message();

  dataset::Dataset camera_only;
  camera_only.name = "loop";
  camera_only.images.push_back({0.0, "0.png"});
  FrontEndSettings fabmap_wifi;
  fabmap_wifi.front_end.kind = FrontEndKind::kFabmap;
  fabmap_wifi.fabmap.localiser.localiser.mode = fabmap::FabmapMode::kWifi;
  s = CheckFrontEndInputs(fabmap_wifi, camera_only);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("fabmap front end needs Wi-Fi scans"), std::string::npos)
      << s.message();
  EXPECT_NE(s.message().find("configs/synthetic.toml"), std::string::npos) << s.message();
  EXPECT_TRUE(CheckFrontEndInputs(classic, camera_only).ok());
}

TEST(FrontEndTest, KindNamesRoundTrip) {
  for (FrontEndKind k : {FrontEndKind::kClassicCamera, FrontEndKind::kFused, FrontEndKind::kFabmap,
                         FrontEndKind::kNone, FrontEndKind::kDescriptors, FrontEndKind::kCustom}) {
    EXPECT_EQ(FrontEndKindFromString(ToString(k)).value(), k);
  }
  EXPECT_FALSE(FrontEndKindFromString("fab_map").ok());
}

// A corridor of 40 places 2 m apart with 10 access points, walked twice; scans every 2 m.
WifiScan CorridorScan(double t, double x, double noise_db) {
  WifiScan s{t, {}};
  for (int k = 0; k < 10; ++k) {
    const double d = std::abs(x - 8.0 * k) + 1.0;
    const double rssi = -30.0 - 25.0 * std::log10(d) + noise_db * std::sin(7.0 * t + k);
    std::string bssid = "ap";
    bssid += std::to_string(k);
    if (rssi > -90.0) s.readings.push_back({bssid, rssi});
  }
  return s;
}

// FABMAP on Wi-Fi words (8 incremental bins, virtual samples from the exploration scans).
FrontEndSettings FabmapWifiSettings() {
  FrontEndSettings settings;
  settings.front_end.kind = FrontEndKind::kFabmap;
  settings.fabmap.localiser.localiser.mode = fabmap::FabmapMode::kWifi;
  settings.fabmap.localiser.wifi_words.bins = 8;
  settings.fabmap.localiser.wifi_words.encoding = fabmap::WifiEncoding::kIncremental;
  settings.fabmap.localiser.virtual_wifi.use_exploration_scans = true;
  settings.fabmap.front_end.recency_s = 30.0;
  return settings;
}

// The corridor walked twice (scans and odometry every 2 s), the second lap noisier.
dataset::Dataset CorridorTwoLaps() {
  dataset::Dataset data;
  for (int lap = 0; lap < 2; ++lap) {
    for (int i = 0; i < 40; ++i) {
      const double t = lap * 100.0 + i * 2.0;
      data.wifi.push_back(CorridorScan(t, 2.0 * i, lap == 0 ? 1.0 : 2.0));
      data.odometry.push_back({t, 1.0, 0.0});
    }
  }
  return data;
}

// Pressure at 10 Hz up to `until_s`, from *next_s on: the second lap one floor (3.5 m) up, the
// climb between 82 and 96 s.
void FeedPressureOneFloorUp(FrontEnd* f, double until_s, double* next_s) {
  for (; *next_s <= until_s; *next_s += 0.1) {
    const double h = *next_s < 82.0 ? 0.0 : std::min(3.5, 3.5 * (*next_s - 82.0) / 14.0);
    EXPECT_TRUE(f->OnPressure(*next_s, 1000.0 * std::exp(-h / 8434.5)).ok());
  }
}

// The two laps through a FABMAP front end (pressure fed when the barometer is on): its
// templates, and the frames of one lap that re-activated (not merely re-used as recent) a
// template made on the other.
struct TwoLapRun {
  std::unique_ptr<FrontEnd> front_end;
  size_t templates = 0;
  int cross_lap = 0;
};
TwoLapRun RunTwoLaps(const FrontEndSettings& settings) {
  const dataset::Dataset data = CorridorTwoLaps();
  TwoLapRun run;
  auto resources = PrepareFabmapResources(settings, data, std::nullopt);
  EXPECT_TRUE(resources.ok());
  if (!resources.ok()) return run;
  run.front_end = CreateFrontEnd(settings, *resources);
  std::vector<int> lap_of_template;
  double next_pressure = 0.0;
  for (size_t i = 0; i < data.wifi.size(); ++i) {
    if (settings.barometer.use_barometer) {
      FeedPressureOneFloorUp(run.front_end.get(), data.wifi[i].time_s, &next_pressure);
    }
    const auto d = run.front_end->OnWifi(data.wifi[i]);
    EXPECT_TRUE(d.ok() && d->has_value());
    if (!d.ok() || !d->has_value()) continue;
    const int lap = i < 40 ? 0 : 1;
    if ((*d)->view.is_new) {
      lap_of_template.push_back(lap);
    } else if (!(*d)->recent) {
      run.cross_lap += lap_of_template[(*d)->view.template_id] != lap;
    }
  }
  run.templates = lap_of_template.size();
  return run;
}

TEST(FabmapFrontEndTest, SecondLapRecognisesTheFirstLapsPlaces) {
  FrontEndSettings settings = FabmapWifiSettings();
  dataset::Dataset data;
  std::vector<double> x_of_scan;
  for (int lap = 0; lap < 2; ++lap) {
    for (int i = 0; i < 40; ++i) {
      const double t = lap * 100.0 + i * 2.0;
      data.wifi.push_back(CorridorScan(t, 2.0 * i, lap == 0 ? 1.0 : 2.0));
      data.odometry.push_back({t, 1.0, 0.0});
      x_of_scan.push_back(2.0 * i);
    }
  }
  const auto resources = PrepareFabmapResources(settings, data, std::nullopt);
  ASSERT_TRUE(resources.ok()) << resources.status().message();
  std::unique_ptr<FrontEnd> a = CreateFrontEnd(settings, *resources);
  EXPECT_FALSE(a->WantsImages());
  std::vector<double> x_of_template;
  int second_lap_matches = 0, close_matches = 0;
  for (size_t i = 0; i < data.wifi.size(); ++i) {
    const auto d = a->OnWifi(data.wifi[i]);
    ASSERT_TRUE(d.ok() && d->has_value());
    const FrameDecision& f = **d;
    if (f.view.is_new) {
      EXPECT_EQ(f.view.template_id, x_of_template.size());
      x_of_template.push_back(x_of_scan[i]);
    } else if (i >= 40 && !f.recent) {
      ++second_lap_matches;
      close_matches += std::abs(x_of_template[f.view.template_id] - x_of_scan[i]) <= 4.0;
      EXPECT_TRUE(f.view.allow_injection);
    }
  }
  EXPECT_GE(x_of_template.size(), 5u);  // the first lap made places
  EXPECT_GE(second_lap_matches, 20);    // the second lap mostly recognises them
  EXPECT_GE(close_matches, second_lap_matches * 9 / 10);

  // The state round-trips: a restored front end decides the same.
  std::unique_ptr<FrontEnd> b = CreateFrontEnd(settings, *resources);
  ASSERT_TRUE(b->DecodeState(a->EncodeState()).ok());
  EXPECT_EQ(b->size(), a->size());
  const WifiScan probe = CorridorScan(300.0, 31.0, 1.5);
  const auto da = a->OnWifi(probe).value();
  const auto db = b->OnWifi(probe).value();
  EXPECT_EQ(da->view.template_id, db->view.template_id);
  std::string corrupt = a->EncodeState();
  corrupt.resize(corrupt.size() - 3);
  EXPECT_FALSE(b->DecodeState(corrupt).ok());
  EXPECT_THROW(CreateFrontEnd(settings, FrontEndResources{}), std::invalid_argument);
}

// decide_by_log_odds: the threshold on the best mapped place's log odds against the new place
// orders the decisions: the higher it is, the more frames become new places (+1000: every
// frame; -1000: only the first, whose map is empty). The floor rule still binds: with the
// barometer and a threshold that accepts anything, the second lap one floor up never matches
// the first lap's places.
TEST(FabmapFrontEndTest, LogOddsThresholdOrdersDecisionsAndKeepsFloors) {
  auto run = [](double threshold, bool barometer) {
    FrontEndSettings settings = FabmapWifiSettings();
    settings.fabmap.front_end.decide_by_log_odds = true;
    settings.fabmap.front_end.match_log_odds = threshold;
    settings.barometer.use_barometer = barometer;
    return RunTwoLaps(settings);
  };
  EXPECT_EQ(run(1000.0, false).templates, 80u);
  EXPECT_EQ(run(-1000.0, false).templates, 1u);
  size_t previous = 80;
  for (double t : {40.0, 20.0, 0.0, -20.0, -40.0}) {
    const size_t templates = run(t, false).templates;
    EXPECT_LE(templates, previous) << t;
    previous = templates;
  }
  EXPECT_LT(previous, run(40.0, false).templates);  // the thresholds made a difference
  // Without the barometer the second lap re-uses the first's places; with it, never.
  EXPECT_GE(run(-1000.0, false).cross_lap, 30);
  EXPECT_EQ(run(-1000.0, true).cross_lap, 0);
}

// The FABMAP front end under the floor rule: a second lap of the same corridor one floor up, with
// the same Wi-Fi (aliased floors). Without the barometer it re-uses the first lap's places; with
// it, none; the floors survive a state round trip.
TEST(FabmapFrontEndTest, BarometerKeepsPlacesOnTheirFloor) {
  auto run = [](bool barometer, std::string* state) {
    FrontEndSettings settings = FabmapWifiSettings();
    settings.barometer.use_barometer = barometer;
    TwoLapRun r = RunTwoLaps(settings);
    if (!r.front_end) return -1;
    const std::unique_ptr<FrontEnd>& f = r.front_end;
    const int cross_floor = r.cross_lap;
    const dataset::Dataset data = CorridorTwoLaps();
    auto resources = PrepareFabmapResources(settings, data, std::nullopt);
    if (state) *state = f->EncodeState();
    if (barometer) {
      std::unique_ptr<FrontEnd> g = CreateFrontEnd(settings, *resources);
      EXPECT_TRUE(g->DecodeState(f->EncodeState()).ok());
      EXPECT_EQ(g->EncodeState(), f->EncodeState());
      EXPECT_EQ(g->TemplateFloor(0), 0);
      EXPECT_EQ(g->TemplateFloor(static_cast<uint32_t>(g->size() - 1)), 1);
      std::string cut = f->EncodeState();
      cut.pop_back();
      EXPECT_FALSE(g->DecodeState(cut).ok());
    }
    return cross_floor;
  };
  std::string state;
  EXPECT_GE(run(false, &state), 15);
  EXPECT_EQ(run(true, &state), 0);
}

TEST(FabmapFrontEndTest, VisionWithoutAModelIsAClearError) {
  FrontEndSettings settings;
  settings.front_end.kind = FrontEndKind::kFabmap;
  settings.fabmap.localiser.localiser.mode = fabmap::FabmapMode::kVision;
  const auto resources = PrepareFabmapResources(settings, dataset::Dataset{}, std::nullopt);
  ASSERT_FALSE(resources.ok());
  EXPECT_NE(resources.status().message().find("visual_model"), std::string::npos);
}

// Two walks of the corridor, the second by a phone that reads 10 dB lower everywhere: a
// difference the eq. 3 kernel (sigma^2 = 20 dB^2) cannot bridge, exp(-100 / 40) = 0.08 < 0.25.
// With the online offset the second walk estimates -10 dB from its own scans and the first
// walk's templates (no ground truth) and then re-visits the first walk's places.
TEST(FusedFrontEndTest, OnlineRssiOffsetBridgesTwoPhones) {
  auto walk = [](bool online, std::vector<double>* offsets, std::string* state) {
    FrontEndSettings settings;
    settings.front_end.kind = FrontEndKind::kFused;
    settings.fused.recency_s = 0.0;
    settings.fused.online_rssi_offset = online;
    std::unique_ptr<FrontEnd> f = CreateFrontEnd(settings);
    std::vector<double> x_of_template;
    int matches = 0, close = 0;
    size_t first_walk_templates = 0;
    for (int session = 0; session < 2; ++session) {
      const double start = 1000.0 * session;
      if (session == 1) first_walk_templates = x_of_template.size();
      for (int i = 0; i < 40; ++i) {
        f->OnSessionStart(start);
        WifiScan scan = CorridorScan(start + 2.0 * i, 2.0 * i, 0.0);
        for (WifiReading& r : scan.readings) r.rssi_dbm -= 10.0 * session;
        const auto d = f->OnWifi(scan);
        EXPECT_TRUE(d.ok() && d->has_value());
        const FrameDecision& decision = **d;
        if (decision.view.is_new) {
          x_of_template.push_back(2.0 * i);
        } else if (session == 1 && decision.view.template_id < first_walk_templates) {
          ++matches;
          close += std::abs(x_of_template[decision.view.template_id] - 2.0 * i) <= 6.0;
        }
      }
    }
    *offsets = f->Report().rssi_offsets_db;
    *state = f->EncodeState();
    return std::make_pair(matches, close);
  };
  std::vector<double> offsets;
  std::string state;
  const auto [plain_matches, plain_close] = walk(false, &offsets, &state);
  EXPECT_EQ(plain_matches, 0);
  EXPECT_TRUE(offsets.empty());
  const auto [matches, close] = walk(true, &offsets, &state);
  ASSERT_EQ(offsets.size(), 2u);
  EXPECT_EQ(offsets[0], 0.0);
  EXPECT_NEAR(offsets[1], -10.0, 1e-4);  // float RSSI
  // The scans after the first ten estimates re-visit the first walk, nearly all within 6 m of
  // the place (a template covers a few metres of corridor; chance on the 78 m corridor: ~15 %).
  EXPECT_GE(matches, 25);
  EXPECT_GE(close, matches * 9 / 10);

  // The estimates are part of the state: a restored front end goes on identically.
  FrontEndSettings settings;
  settings.front_end.kind = FrontEndKind::kFused;
  settings.fused.recency_s = 0.0;
  settings.fused.online_rssi_offset = true;
  std::unique_ptr<FrontEnd> restored = CreateFrontEnd(settings);
  ASSERT_TRUE(restored->DecodeState(state).ok());
  EXPECT_EQ(restored->Report().rssi_offsets_db, offsets);
  EXPECT_EQ(restored->EncodeState(), state);
  std::string truncated = state;
  truncated.pop_back();
  EXPECT_FALSE(restored->DecodeState(truncated).ok());
  // Without the option the state has the format of earlier releases (shorter).
  settings.fused.online_rssi_offset = false;
  EXPECT_FALSE(CreateFrontEnd(settings)->DecodeState(state).ok());
}

// The second phone reads 10 dB lower while walking, and 16 dB lower during the 15 scans before
// its walk, while it stands at the corridor's start and is waved (body shadow, the gesture). An
// offset learnt from every scan is the standing scans' -16 dB until the walking estimates
// outnumber them; learnt only from walking scans it is the walk's -10 dB from its tenth scan on.
TEST(FusedFrontEndTest, OnlineRssiOffsetCanLearnFromWalkingScansOnly) {
  for (bool walking_only : {false, true}) {
    FrontEndSettings settings;
    settings.front_end.kind = FrontEndKind::kFused;
    settings.fused.recency_s = 0.0;
    settings.fused.online_rssi_offset = true;
    settings.fused.rssi_offset_walking_only = walking_only;
    std::unique_ptr<FrontEnd> f = CreateFrontEnd(settings);
    for (int i = 0; i < 40; ++i) {  // the first phone maps the corridor
      f->OnSessionStart(0.0);
      f->OnWalking(true);
      ASSERT_TRUE(f->OnWifi(CorridorScan(2.0 * i, 2.0 * i, 0.0)).ok());
    }
    auto scan = [&](double t, double x, double shift_db, bool walking) {
      f->OnSessionStart(1000.0);
      f->OnWalking(walking);
      WifiScan s = CorridorScan(t, x, 0.0);
      for (WifiReading& r : s.readings) r.rssi_dbm += shift_db;
      ASSERT_TRUE(f->OnWifi(s).ok());
    };
    for (int i = 0; i < 15; ++i) scan(1000.0 + i, 0.0, -16.0, false);
    for (int i = 0; i < 10; ++i) scan(1020.0 + 2.0 * i, 2.0 * i, -10.0, true);
    const std::vector<double> offsets = f->Report().rssi_offsets_db;
    ASSERT_EQ(offsets.size(), 2u);
    // Within half a dB: a scan's best template is a few metres off now and then.
    EXPECT_NEAR(offsets[1], walking_only ? -10.0 : -16.0, 0.5) << walking_only;
  }
}

// Localising on a saved map, the map's templates are the reference: a scan that matches one of
// them is that place, even when a template made since (a place the map does not hold, here the
// same corridor spot read 8 dB lower before any offset was known) matches it better. While
// mapping, the better match wins as eq. 9 says.
TEST(FusedFrontEndTest, LocalisingPrefersTheMapsTemplates) {
  for (bool localising : {false, true}) {
    FrontEndSettings settings;
    settings.front_end.kind = FrontEndKind::kFused;
    settings.fused.use_camera = false;
    settings.fused.recency_s = 0.0;
    std::unique_ptr<FrontEnd> f = CreateFrontEnd(settings);
    auto at = [&](double t, double offset_db) {
      WifiScan scan = CorridorScan(t, 20.0, 0.0);
      for (WifiReading& r : scan.readings) r.rssi_dbm += offset_db;
      const auto d = f->OnWifi(scan);
      EXPECT_TRUE(d.ok() && d->has_value());
      return d->value_or(FrameDecision{});
    };
    ASSERT_TRUE(at(0.0, 0.0).view.is_new);  // the map: template 0
    if (localising) f->SettleForLocalisation();
    const FrameDecision quieter = at(10.0, -8.0);
    ASSERT_TRUE(quieter.view.is_new) << "8 dB must be too far for a match";
    ASSERT_EQ(quieter.view.template_id, 1u);
    const FrameDecision between = at(20.0, -5.0);  // 5 dB from template 0, 3 dB from template 1
    EXPECT_FALSE(between.view.is_new);
    EXPECT_EQ(between.source, DecisionSource::kWifi);
    EXPECT_EQ(between.view.template_id, localising ? 0u : 1u) << "localising " << localising;
  }
}

// The FABMAP front end with the same two phones: the second walk reads 15 dB lower, about two of
// the eight RSSI bins, so its scans are other words. With the online offset (estimated from the
// scans against the first walk's places, no ground truth) the second walk's scans become the
// first walk's words again and re-visit its places; the estimate is part of the state.
TEST(FabmapFrontEndTest, OnlineRssiOffsetBridgesTwoPhones) {
  constexpr double kShiftDb = -15.0;
  dataset::Dataset data;
  std::vector<double> x_of_scan;
  for (int session = 0; session < 2; ++session) {
    for (int i = 0; i < 40; ++i) {
      const double t = 1000.0 * session + 2.0 * i;
      WifiScan scan = CorridorScan(t, 2.0 * i, 1.0);
      for (WifiReading& r : scan.readings) r.rssi_dbm += kShiftDb * session;
      data.wifi.push_back(scan);
      data.odometry.push_back({t, 1.0, 0.0});
      x_of_scan.push_back(2.0 * i);
    }
  }
  struct Walk {
    int matches = 0, close = 0;
    std::vector<double> offsets;
    std::string state;
  };
  auto walk = [&](bool online) {
    FrontEndSettings settings = FabmapWifiSettings();
    settings.fabmap.front_end.online_rssi_offset = online;
    const auto resources = PrepareFabmapResources(settings, data, std::nullopt);
    EXPECT_TRUE(resources.ok());
    std::unique_ptr<FrontEnd> f = CreateFrontEnd(settings, *resources);
    Walk w;
    std::vector<double> x_of_template;
    size_t first_walk_templates = 0;
    for (size_t i = 0; i < data.wifi.size(); ++i) {
      if (i == 40) first_walk_templates = x_of_template.size();
      f->OnSessionStart(i < 40 ? 0.0 : 1000.0);
      const auto d = f->OnWifi(data.wifi[i]);
      EXPECT_TRUE(d.ok() && d->has_value());
      if (!d.ok() || !d->has_value()) continue;
      const FrameDecision& decision = **d;
      if (decision.view.is_new) {
        x_of_template.push_back(x_of_scan[i]);
      } else if (i >= 40 && decision.view.template_id < first_walk_templates) {
        ++w.matches;
        w.close += std::abs(x_of_template[decision.view.template_id] - x_of_scan[i]) <= 6.0;
      }
    }
    w.offsets = f->Report().rssi_offsets_db;
    w.state = f->EncodeState();
    return w;
  };
  const Walk plain = walk(false);
  EXPECT_TRUE(plain.offsets.empty());
  const Walk online = walk(true);
  ASSERT_EQ(online.offsets.size(), 2u);
  EXPECT_EQ(online.offsets[0], 0.0);
  EXPECT_NEAR(online.offsets[1], kShiftDb, 1.0);  // the noise is +-1 dB per AP
  // Chance of a match within 6 m on the 78 m corridor is ~15 %.
  EXPECT_GE(online.matches, 20) << "plain: " << plain.matches;
  EXPECT_GE(online.close, online.matches * 9 / 10);
  EXPECT_GE(online.close, 2 * plain.close + 10) << "plain: " << plain.close;

  // A restored front end holds the same estimates and writes the same state.
  FrontEndSettings settings = FabmapWifiSettings();
  settings.fabmap.front_end.online_rssi_offset = true;
  const auto resources = PrepareFabmapResources(settings, data, std::nullopt);
  ASSERT_TRUE(resources.ok());
  std::unique_ptr<FrontEnd> restored = CreateFrontEnd(settings, *resources);
  ASSERT_TRUE(restored->DecodeState(online.state).ok());
  EXPECT_EQ(restored->Report().rssi_offsets_db, online.offsets);
  EXPECT_EQ(restored->EncodeState(), online.state);
  std::string truncated = online.state;
  truncated.pop_back();
  EXPECT_FALSE(restored->DecodeState(truncated).ok());
}

// Two walks of the corridor as two sessions, the second with another phone (its readings 6 dB
// lower and noisier): its revisits agree less with the first walk's places than a walk's own
// revisits do. Each scan's decision, the session starts announced as replay does.
struct SessionRun {
  std::vector<FrameDecision> decisions;
  size_t first_walk_templates = 0;
  int cross = 0, cross_close = 0;  // second-walk frames re-activating a first-walk place (<= 6 m)
  std::string state_at_60;         // the state after scan 60 (mid second walk)
  FrontEndReport report;           // at the end
};
// With `verify`, each second-walk scan is then confirmed as a revisit of the first walk's scan at
// the same place (OnVerifiedRevisit), as the Wi-Fi sequence loop closer would.
SessionRun RunTwoSessions(const FrontEndSettings& settings, const std::string& restore_at_60 = "",
                          bool verify = false, const FrontEndCalibration* calibration = nullptr) {
  dataset::Dataset data;
  std::vector<double> x_of_scan;
  for (int session = 0; session < 2; ++session) {
    for (int i = 0; i < 40; ++i) {
      const double t = 1000.0 * session + 2.0 * i;
      WifiScan scan = CorridorScan(t, 2.0 * i, session == 0 ? 1.0 : 2.5);
      for (WifiReading& r : scan.readings) r.rssi_dbm -= 6.0 * session;
      data.wifi.push_back(scan);
      data.odometry.push_back({t, 1.0, 0.0});
      x_of_scan.push_back(2.0 * i);
    }
  }
  SessionRun run;
  const auto resources = PrepareFabmapResources(settings, data, std::nullopt);
  EXPECT_TRUE(resources.ok());
  if (!resources.ok()) return run;
  std::unique_ptr<FrontEnd> f = CreateFrontEnd(settings, *resources);
  if (calibration != nullptr) {
    const Status calibrated = f->Calibrate(*calibration);
    EXPECT_TRUE(calibrated.ok()) << calibrated.message();
  }
  std::vector<double> x_of_template;
  for (size_t i = 0; i < data.wifi.size(); ++i) {
    if (i == 40) run.first_walk_templates = x_of_template.size();
    if (i == 61 && !restore_at_60.empty()) {
      f = CreateFrontEnd(settings, *resources);
      const Status restored = f->DecodeState(restore_at_60);
      EXPECT_TRUE(restored.ok()) << restored.message();
    }
    f->OnSessionStart(i < 40 ? 0.0 : 1000.0);
    const auto d = f->OnWifi(data.wifi[i]);
    EXPECT_TRUE(d.ok() && d->has_value());
    if (!d.ok() || !d->has_value()) return run;
    const FrameDecision& decision = **d;
    run.decisions.push_back(decision);
    if (decision.view.is_new) {
      x_of_template.push_back(x_of_scan[i]);
    } else if (i >= 40 && decision.view.template_id < run.first_walk_templates) {
      ++run.cross;
      run.cross_close += std::abs(x_of_template[decision.view.template_id] - x_of_scan[i]) <= 6.0;
    }
    if (verify && i >= 40) f->OnVerifiedRevisit(data.wifi[i].time_s, data.wifi[i - 40].time_s);
    if (i == 60) run.state_at_60 = f->EncodeState();
  }
  run.report = f->Report();
  return run;
}

bool SameDecisions(const SessionRun& a, const SessionRun& b) {
  if (a.decisions.size() != b.decisions.size()) return false;
  for (size_t i = 0; i < a.decisions.size(); ++i) {
    const FrameDecision& x = a.decisions[i];
    const FrameDecision& y = b.decisions[i];
    if (x.view.template_id != y.view.template_id || x.view.is_new != y.view.is_new ||
        x.recent != y.recent || x.view.allow_injection != y.view.allow_injection) {
      return false;
    }
  }
  return true;
}

// earlier_sessions_apart: the second walk's places are judged by match_log_odds, the first
// walk's by earlier_session_log_odds. With both thresholds equal it decides exactly as the one
// threshold does (the oracle); the first walk (no earlier session) never depends on the second
// threshold; a lower earlier-session threshold lets the other phone's walk re-activate the first
// walk's places (at the right place), a higher one stops it; a restored state decides the same.
TEST(FabmapFrontEndTest, EarlierSessionsHaveTheirOwnThreshold) {
  auto settings = [](double same, std::optional<double> earlier) {
    FrontEndSettings s = FabmapWifiSettings();
    s.fabmap.front_end.decide_by_log_odds = true;
    s.fabmap.front_end.match_log_odds = same;
    s.fabmap.front_end.earlier_sessions_apart = earlier.has_value();
    s.fabmap.front_end.earlier_session_log_odds = earlier.value_or(0.0);
    return s;
  };
  for (double t : {-20.0, 0.0, 10.0}) {
    EXPECT_TRUE(
        SameDecisions(RunTwoSessions(settings(t, std::nullopt)), RunTwoSessions(settings(t, t))))
        << t;
  }
  const SessionRun one = RunTwoSessions(settings(0.0, std::nullopt));
  constexpr double kEarlier = -5.0;
  const SessionRun low = RunTwoSessions(settings(0.0, kEarlier));
  const SessionRun high = RunTwoSessions(settings(0.0, 1000.0));
  SessionRun first_walk = low;
  first_walk.decisions.resize(40);
  SessionRun first_walk_one = one;
  first_walk_one.decisions.resize(40);
  EXPECT_TRUE(SameDecisions(first_walk, first_walk_one));
  // Measured: one threshold (0) 4 of 40 second-walk frames re-activate a first-walk place, 4
  // within 6 m; at -5 for earlier sessions 24, 23 within 6 m (chance of 6 m on the 78 m
  // corridor: about 15 %).
  EXPECT_EQ(high.cross, 0);
  EXPECT_GE(low.cross_close, one.cross_close + 10);
  EXPECT_GE(low.cross_close, low.cross * 3 / 4);

  // Restored from the state after scan 60, the run goes on as the uninterrupted one.
  EXPECT_TRUE(SameDecisions(RunTwoSessions(settings(0.0, kEarlier), low.state_at_60), low));
  std::string truncated = low.state_at_60;
  truncated.pop_back();
  const auto resources =
      PrepareFabmapResources(settings(0.0, kEarlier), CorridorTwoLaps(), std::nullopt);
  ASSERT_TRUE(resources.ok());
  EXPECT_FALSE(CreateFrontEnd(settings(0.0, kEarlier), *resources)->DecodeState(truncated).ok());

  FabmapFrontEndOptions needs_log_odds;
  needs_log_odds.earlier_sessions_apart = true;
  std::string error;
  EXPECT_FALSE(needs_log_odds.IsValid(&error));
  EXPECT_NE(error.find("decide_by_log_odds"), std::string::npos) << error;
}

// learn_earlier_session_log_odds: starting from a threshold that accepts no earlier place
// (+1000 nats), the second walk (the other phone) learns one from revisits verified outside the
// front end, here the true pairs (scan i of the second walk shows the place of scan i of the
// first): once learn_min_revisits are known, its scans re-activate the first walk's places, at
// the right place. Without the verified revisits nothing is learnt; a restored state carries the
// revisits and the threshold.
TEST(FabmapFrontEndTest, EarlierSessionThresholdIsLearntFromVerifiedRevisits) {
  FrontEndSettings settings = FabmapWifiSettings();
  settings.fabmap.front_end.decide_by_log_odds = true;
  settings.fabmap.front_end.earlier_sessions_apart = true;
  settings.fabmap.front_end.earlier_session_log_odds = 1000.0;
  settings.fabmap.front_end.learn_earlier_session_log_odds = true;
  settings.fabmap.front_end.learn_min_revisits = 5;
  settings.fabmap.front_end.learn_near_recall = 0.9;
  const SessionRun unverified = RunTwoSessions(settings);
  EXPECT_EQ(unverified.cross, 0);
  ASSERT_TRUE(unverified.report.fabmap_learning.has_value());
  EXPECT_EQ(unverified.report.fabmap_learning->verified_revisits, 0u);
  EXPECT_EQ(unverified.report.fabmap_learning->earlier_session_log_odds, 1000.0);

  const SessionRun learnt = RunTwoSessions(settings, "", /*verify=*/true);
  ASSERT_TRUE(learnt.report.fabmap_learning.has_value());
  const auto& l = *learnt.report.fabmap_learning;
  // Every second-walk scan was verified against a first-walk place; none is unscorable here.
  EXPECT_EQ(l.verified_revisits, 40u);
  ASSERT_TRUE(l.earlier_session_log_odds.has_value());
  EXPECT_LT(*l.earlier_session_log_odds, 0.0);  // these revisits lose to the new place
  // The first 5 scans teach; of the 35 after them most re-activate a first-walk place within 6 m
  // (chance about 15 %; measured: -13.2 nats learnt, 33 such frames, 26 within 6 m).
  EXPECT_GE(learnt.cross_close, 20);
  EXPECT_GE(learnt.cross_close, learnt.cross * 3 / 4);

  // Learnt again from the same revisits: the restored front end reports the same threshold and
  // writes the same state.
  const auto resources = PrepareFabmapResources(settings, CorridorTwoLaps(), std::nullopt);
  ASSERT_TRUE(resources.ok());
  std::unique_ptr<FrontEnd> restored = CreateFrontEnd(settings, *resources);
  ASSERT_TRUE(restored->DecodeState(learnt.state_at_60).ok());
  EXPECT_EQ(restored->EncodeState(), learnt.state_at_60);
  EXPECT_TRUE(SameDecisions(RunTwoSessions(settings, learnt.state_at_60, true), learnt));
  std::string bad = learnt.state_at_60;
  bad.resize(bad.size() / 2);
  EXPECT_FALSE(restored->DecodeState(bad).ok());
  // The state ends with the revisits' scores (no barometer here): an infinite one is refused.
  std::string infinite = learnt.state_at_60;
  const double inf = std::numeric_limits<double>::infinity();
  std::memcpy(infinite.data() + infinite.size() - sizeof inf, &inf, sizeof inf);
  const Status refused = restored->DecodeState(infinite);
  EXPECT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("not finite"), std::string::npos) << refused.message();

  FabmapFrontEndOptions needs_apart;
  needs_apart.decide_by_log_odds = true;
  needs_apart.learn_earlier_session_log_odds = true;
  std::string error;
  EXPECT_FALSE(needs_apart.IsValid(&error));
  EXPECT_NE(error.find("earlier_sessions_apart"), std::string::npos) << error;
}

// calibrate_earlier_session_log_odds: a calibration handed over before the first scan is the
// earlier sessions' threshold from the first frame on, so the decisions equal those of a front
// end configured with that value (the oracle); the saved state carries it, so a front end
// restored from it (never calibrated itself) goes on the same; a calibration without a learnt
// value leaves the configured one. Refused: after the first scan, non-finite, to a front end
// without the option, and the option beside in-run learning or without Wi-Fi alone.
TEST(FabmapFrontEndTest, CalibrationIsTheThresholdFromTheFirstFrame) {
  FrontEndSettings configured = FabmapWifiSettings();
  configured.fabmap.front_end.decide_by_log_odds = true;
  configured.fabmap.front_end.earlier_sessions_apart = true;
  configured.fabmap.front_end.earlier_session_log_odds = -5.0;
  FrontEndSettings calibrated = configured;
  calibrated.fabmap.front_end.earlier_session_log_odds = 1000.0;
  calibrated.fabmap.front_end.calibrate_earlier_session_log_odds = true;

  const FrontEndCalibration learnt{-5.0, 17};
  const SessionRun run = RunTwoSessions(calibrated, "", false, &learnt);
  const SessionRun oracle = RunTwoSessions(configured);
  EXPECT_TRUE(SameDecisions(run, oracle));
  EXPECT_GE(run.cross_close, 10);  // -5 nats re-activates the first walk (measured: 23 of 24)
  ASSERT_TRUE(run.report.fabmap_learning.has_value());
  EXPECT_EQ(run.report.fabmap_learning->earlier_session_log_odds, -5.0);
  EXPECT_EQ(run.report.fabmap_learning->verified_revisits, 17u);
  EXPECT_EQ(run.report.fabmap_learning->calibrated, true);
  // Restored after scan 60 into a front end that was never calibrated (its decisions before the
  // restore are the uncalibrated ones; from scan 61 on they are the calibrated run's).
  SessionRun restored = RunTwoSessions(calibrated, run.state_at_60);
  SessionRun after_restore = run;
  for (SessionRun* r : {&restored, &after_restore}) {
    r->decisions.erase(r->decisions.begin(), r->decisions.begin() + 61);
  }
  EXPECT_TRUE(SameDecisions(restored, after_restore));
  EXPECT_EQ(restored.report.fabmap_learning->calibrated, true);

  const FrontEndCalibration too_few{std::nullopt, 3};
  const SessionRun fallback = RunTwoSessions(calibrated, "", false, &too_few);
  EXPECT_EQ(fallback.cross, 0);  // +1000 nats, as configured
  EXPECT_EQ(fallback.report.fabmap_learning->earlier_session_log_odds, 1000.0);
  EXPECT_EQ(fallback.report.fabmap_learning->calibrated, false);
  EXPECT_EQ(fallback.report.fabmap_learning->verified_revisits, 3u);

  const auto resources = PrepareFabmapResources(calibrated, CorridorTwoLaps(), std::nullopt);
  ASSERT_TRUE(resources.ok());
  std::unique_ptr<FrontEnd> started = CreateFrontEnd(calibrated, *resources);
  ASSERT_TRUE(started->OnWifi(CorridorTwoLaps().wifi.front()).ok());
  EXPECT_FALSE(started->Calibrate(learnt).ok());
  const FrontEndCalibration infinite{std::numeric_limits<double>::infinity(), 17};
  EXPECT_FALSE(CreateFrontEnd(calibrated, *resources)->Calibrate(infinite).ok());
  EXPECT_FALSE(CreateFrontEnd(configured, *resources)->Calibrate(learnt).ok());
  EXPECT_FALSE(CreateFrontEnd(FrontEndSettings())->Calibrate(learnt).ok());  // classic camera

  std::string error;
  FabmapFrontEndOptions both = calibrated.fabmap.front_end;
  both.learn_earlier_session_log_odds = true;
  EXPECT_FALSE(both.IsValid(&error));
  EXPECT_NE(error.find("learn_earlier_session_log_odds = false"), std::string::npos) << error;
  FabmapFrontEndOptions not_apart = calibrated.fabmap.front_end;
  not_apart.earlier_sessions_apart = false;
  EXPECT_FALSE(not_apart.IsValid(&error));
  EXPECT_NE(error.find("earlier_sessions_apart"), std::string::npos) << error;
  FabmapSettings with_vision = calibrated.fabmap;
  with_vision.localiser.localiser.mode = fabmap::FabmapMode::kEarly;
  EXPECT_FALSE(with_vision.IsValid(&error));
  EXPECT_NE(error.find("Wi-Fi alone"), std::string::npos) << error;
}

// Access points replaced one by one over months: in session s (0 to 6) the APs ap0 .. ap(s-1) of
// the corridor are gone and new ones new0 .. new(s-1) hang 4 m further along, with the same
// propagation. Each session walks the corridor once. Returns the share of the last session's
// scans matched to a template of the first session (the original map recognised), and the APs
// added and dropped by revisits.
std::pair<double, std::pair<uint64_t, uint64_t>> MonthsOfApChanges(double update_weight,
                                                                   bool neutral,
                                                                   std::string* state = nullptr) {
  FrontEndSettings settings;
  settings.front_end.kind = FrontEndKind::kFused;
  settings.fused.recency_s = 0.0;
  settings.fused.revisit_update_weight = update_weight;
  settings.wifi.unmapped_aps_neutral = neutral;
  std::unique_ptr<FrontEnd> f = CreateFrontEnd(settings);
  size_t first_session_templates = 0;
  int recognised = 0, scans = 0;
  constexpr int kSessions = 7;
  for (int session = 0; session < kSessions; ++session) {
    const double start = 1000.0 * session;
    for (int i = 0; i < 37; ++i) {
      f->OnSessionStart(start);
      const double x = 2.0 * i;
      WifiScan scan{start + 2.0 * i, {}};
      for (int k = 0; k < 10; ++k) {
        const bool replaced = k < session;
        const double ap_x = 8.0 * k + (replaced ? 4.0 : 0.0);
        const double rssi = -30.0 - 25.0 * std::log10(std::abs(x - ap_x) + 1.0);
        if (rssi > -90.0) {
          scan.readings.push_back({(replaced ? "new" : "ap") + std::to_string(k), rssi});
        }
      }
      const auto d = f->OnWifi(scan);
      EXPECT_TRUE(d.ok() && d->has_value());
      if (session == 0) first_session_templates = f->size();
      if (session == kSessions - 1) {
        ++scans;
        recognised += !(*d)->view.is_new && (*d)->view.template_id < first_session_templates;
      }
    }
  }
  if (state) *state = f->EncodeState();
  return {static_cast<double>(recognised) / scans,
          f->Report().revisit_ap_updates.value_or(std::pair<uint64_t, uint64_t>(0, 0))};
}

// Without updates the last session, six of ten APs replaced, recognises none of the first
// session's templates: each revisit misses strong stored APs (eq. 5) and hears strong new ones
// (eq. 4). With revisit_update_weight every sure revisit moves its template along, so the
// changes arrive one AP at a time and the original map is still recognised (measured: 35 % of
// the last walk's scans; 49 % with unmapped_aps_neutral, where a new AP no template holds yet
// costs nothing). We require a fifth, and the state to carry the updated fingerprints.
TEST(FusedFrontEndTest, RevisitsFollowAccessPointChanges) {
  for (bool neutral : {false, true}) {
    const auto [plain, plain_updates] = MonthsOfApChanges(0.0, neutral);
    EXPECT_EQ(plain, 0.0) << neutral;
    EXPECT_EQ(plain_updates.first + plain_updates.second, 0u);
    std::string state;
    const auto [following, updates] = MonthsOfApChanges(0.25, neutral, &state);
    EXPECT_GE(following, 0.2) << neutral;
    EXPECT_GT(updates.first, 0u);
    EXPECT_GT(updates.second, 0u);
    // A restored front end holds the same updated fingerprints and counts.
    FrontEndSettings settings;
    settings.front_end.kind = FrontEndKind::kFused;
    settings.fused.recency_s = 0.0;
    settings.fused.revisit_update_weight = 0.25;
    settings.wifi.unmapped_aps_neutral = neutral;
    std::unique_ptr<FrontEnd> restored = CreateFrontEnd(settings);
    ASSERT_TRUE(restored->DecodeState(state).ok());
    EXPECT_EQ(restored->EncodeState(), state);
    EXPECT_EQ(restored->Report().revisit_ap_updates, updates);
    std::string truncated = state;
    truncated.pop_back();
    EXPECT_FALSE(restored->DecodeState(truncated).ok());
  }
}

// A walk through a two-storey building for the floor rule: scans every 2 s along a 78 m
// corridor; `height(t)` gives the barometer (10 Hz) through the hypsometric formula.
class FloorWalk {
 public:
  FloorWalk(bool barometer, int min_votes = 3) {
    settings_.front_end.kind = FrontEndKind::kFused;
    settings_.fused.recency_s = 0.0;
    settings_.barometer.use_barometer = barometer;
    settings_.barometer.floor_offset_min_votes = min_votes;
    front_end = CreateFrontEnd(settings_);
  }
  // Pressure readings up to `t`, then the scan; returns the decision.
  FrameDecision Scan(double t, const WifiScan& scan, const std::function<double(double)>& height) {
    for (; next_pressure_s_ <= t; next_pressure_s_ += 0.1) {
      const double h = height(next_pressure_s_);
      EXPECT_TRUE(front_end->OnPressure(next_pressure_s_, 1000.0 * std::exp(-h / 8434.5)).ok());
    }
    const auto d = front_end->OnWifi(scan);
    EXPECT_TRUE(d.ok() && d->has_value());
    return **d;
  }
  void StartSession(double start_s) {
    front_end->OnSessionStart(start_s);
    next_pressure_s_ = start_s;
  }
  FrontEndSettings settings_;
  std::unique_ptr<FrontEnd> front_end;
  double next_pressure_s_ = 0.0;
};

// Floor 0 and floor 1 have the same Wi-Fi (the APs of one floor heard through the ceiling). The
// walk goes along floor 0, up 3.5 m of stairs in 14 s, along floor 1 and back. A match is across
// floors when the true heights of its two ends differ by more than half a storey.
double TwoStoreys(double t) { return t < 80.0 ? 0.0 : (t < 94.0 ? 3.5 * (t - 80.0) / 14.0 : 3.5); }

TEST(FusedFrontEndTest, BarometerKeepsMatchesOnTheirFloor) {
  auto height = TwoStoreys;
  auto walk = [&](bool barometer, std::string* state_mid, std::vector<int>* floors_of_templates) {
    FloorWalk w(barometer);
    std::vector<double> made_at_height;  // by template
    int cross_floor = 0, same_floor = 0;
    auto step = [&](double t, double x) {
      const FrameDecision d = w.Scan(t, CorridorScan(t, x, 0.5), height);
      if (d.view.is_new) {
        made_at_height.push_back(height(t));
      } else if (!d.recent) {
        (std::abs(made_at_height[d.view.template_id] - height(t)) > 1.75 ? cross_floor
                                                                         : same_floor) += 1;
      }
    };
    for (int i = 0; i < 40; ++i) step(2.0 * i, 2.0 * i);     // floor 0
    for (int i = 0; i < 7; ++i) step(80.0 + 2.0 * i, 78.0);  // stairs
    if (state_mid) *state_mid = w.front_end->EncodeState();
    for (int i = 0; i < 40; ++i) step(94.0 + 2.0 * i, 78.0 - 2.0 * i);  // floor 1, back
    for (int i = 0; i < 40; ++i) step(174.0 + 2.0 * i, 2.0 * i);        // floor 1 again
    if (floors_of_templates) {
      for (uint32_t id = 0; id < made_at_height.size(); ++id) {
        const std::optional<int> f = w.front_end->TemplateFloor(id);
        floors_of_templates->push_back(f ? *f : -1);
        // A floor, when known, is the true one; made mid-stairs, none.
        const double h = made_at_height[id];
        if (h > 0.5 && h < 3.0) {
          EXPECT_FALSE(f.has_value()) << id;
        } else if (f) {
          EXPECT_EQ(*f, h > 1.75 ? 1 : 0) << id;
        }
      }
    }
    return std::make_pair(cross_floor, same_floor);
  };
  const auto [plain_cross, plain_same] = walk(false, nullptr, nullptr);
  EXPECT_GE(plain_cross, 40);  // floor 1 re-uses floor 0's templates
  std::string state_mid;
  std::vector<int> floors;
  const auto [cross, same] = walk(true, &state_mid, &floors);
  EXPECT_EQ(cross, 0);
  EXPECT_GE(same, 35);  // the second pass on floor 1 re-uses floor 1's templates
  EXPECT_GE(std::count(floors.begin(), floors.end(), 0), 5);
  EXPECT_GE(std::count(floors.begin(), floors.end(), 1), 5);

  // The floors are part of the state: a front end restored halfway goes on identically.
  FloorWalk original(true), restored(true);
  for (int i = 0; i < 40; ++i) original.Scan(2.0 * i, CorridorScan(2.0 * i, 2.0 * i, 0.5), height);
  for (int i = 0; i < 7; ++i) {
    original.Scan(80.0 + 2.0 * i, CorridorScan(80.0 + 2.0 * i, 78.0, 0.5), height);
  }
  ASSERT_EQ(original.front_end->EncodeState(), state_mid);
  ASSERT_TRUE(restored.front_end->DecodeState(state_mid).ok());
  EXPECT_EQ(restored.front_end->EncodeState(), state_mid);
  restored.next_pressure_s_ = original.next_pressure_s_;
  for (int i = 0; i < 40; ++i) {
    const double t = 94.0 + 2.0 * i;
    const FrameDecision a = original.Scan(t, CorridorScan(t, 78.0 - 2.0 * i, 0.5), height);
    const FrameDecision b = restored.Scan(t, CorridorScan(t, 78.0 - 2.0 * i, 0.5), height);
    EXPECT_EQ(a.view.template_id, b.view.template_id);
    EXPECT_EQ(a.view.is_new, b.view.is_new);
  }
  EXPECT_EQ(restored.front_end->EncodeState(), original.front_end->EncodeState());
  for (size_t cut : {size_t{1}, size_t{9}, state_mid.size() / 2}) {
    EXPECT_FALSE(restored.front_end->DecodeState(state_mid.substr(0, state_mid.size() - cut)).ok());
  }
  // Without the option the state has the format of earlier releases (shorter).
  EXPECT_FALSE(FloorWalk(false).front_end->DecodeState(state_mid).ok());
  // A reading the tracker refuses is an error, not a crash.
  EXPECT_FALSE(restored.front_end->OnPressure(1.0, 1000.0).ok());  // time goes backwards
  EXPECT_FALSE(restored.front_end->OnPressure(1e6, 5000.0).ok());  // not a pressure
}

// Two floors with different APs. A second walk starts upstairs: its first level is taken for the
// first walk's floor 0 until its Wi-Fi matches vote it onto floor 1.
TEST(FusedFrontEndTest, SecondSessionsFloorOffsetComesFromWifiVotes) {
  auto floor_scan = [](double t, double x, int floor) {
    WifiScan s = CorridorScan(t, x, 0.5);
    if (floor == 1) {
      for (WifiReading& r : s.readings) r.bssid = "up-" + r.bssid;
    }
    return s;
  };
  FloorWalk w(true, 3);
  auto first = TwoStoreys;
  std::vector<std::pair<uint32_t, int>> session_of_template;  // (session, true floor)
  auto record = [&](const FrameDecision& d, uint32_t session, int floor) {
    if (d.view.is_new) session_of_template.emplace_back(session, floor);
  };
  w.StartSession(0.0);
  for (int i = 0; i < 40; ++i)
    record(w.Scan(2.0 * i, floor_scan(2.0 * i, 2.0 * i, 0), first), 0, 0);
  for (int i = 0; i < 7; ++i) {  // the stairs: downstairs APs, then upstairs ones
    const double t = 80.0 + 2.0 * i;
    record(w.Scan(t, floor_scan(t, 78.0, i < 4 ? 0 : 1), first), 0, i == 0 ? 0 : -1);
  }
  for (int i = 0; i < 40; ++i) {
    const double t = 94.0 + 2.0 * i;
    record(w.Scan(t, floor_scan(t, 78.0 - 2.0 * i, 1), first), 0, 1);
  }
  // The second walk: level all the way (its own floor 0), on the first walk's floor 1.
  w.StartSession(1000.0);
  int matched_before = 0, matched_after = 0, cross_floor = 0;
  for (int i = 0; i < 40; ++i) {
    const double t = 1000.0 + 2.0 * i;
    const FrameDecision d = w.Scan(t, floor_scan(t, 2.0 * i, 1), [](double) { return 0.0; });
    record(d, 1, 1);
    if (d.view.is_new || d.recent) continue;
    const auto [session, floor] = session_of_template[d.view.template_id];
    if (session == 0) {
      (i < 2 ? matched_before : matched_after) += 1;
      cross_floor += floor != 1;
    }
  }
  const std::optional<FloorReport> report = w.front_end->Report().floors;
  ASSERT_TRUE(report.has_value());
  EXPECT_EQ(report->session_floor_offsets, (std::vector<int>{0, 1}));
  EXPECT_EQ(report->floor_offset_changes, 1u);
  EXPECT_EQ(matched_before,
            0);  // the third scan's vote moves the offset; before, floor 1 is refused
  EXPECT_GE(matched_after, 30);
  EXPECT_EQ(cross_floor, 0);
  for (uint32_t id = 0; id < session_of_template.size(); ++id) {
    if (session_of_template[id].first == 1) {
      EXPECT_EQ(w.front_end->TemplateFloor(id), 1) << id;
    }
  }
}

}  // namespace
}  // namespace ratslam::fusion

namespace ratslam::fusion {
namespace {

// A 64x32 image per place (blocks of 4x4 pixels, so that block means differ between places); on
// the second lap the same place darker, flatter and noisy.
GrayImage Place(int place, int lap, Random* noise) {
  Random texture(7000 + static_cast<uint64_t>(place));
  std::vector<double> blocks(16 * 8);
  for (double& b : blocks) b = texture.Uniform(20, 230);
  GrayImage image{64, 32, std::vector<uint8_t>(64 * 32)};
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 64; ++x) {
      const double p = blocks[(y / 4) * 16 + x / 4];
      const double seen = lap == 0 ? p : 40 + 0.5 * p + noise->Gaussian(0, 10);
      image.pixels[y * 64 + x] = static_cast<uint8_t>(std::clamp(std::lround(seen), 0L, 255L));
    }
  }
  return image;
}

FrontEndSettings SequenceSettings(bool recognise) {
  FrontEndSettings s;
  s.front_end.kind = FrontEndKind::kClassicCamera;
  s.sequence.recognise_views = recognise;
  s.sequence.recency_frames = 30;
  s.sequence.min_references = 60;
  return s;
}

// One route of 150 places driven twice, the second time in other light. The classic camera alone
// recognises nothing on the second lap (every frame a new template); with sequence recognition
// the first lap still makes a template per place and never claims one of its own, every
// second-lap frame whose sequence is full (and continues the previous frame's line) is
// recognised, and every recognised frame re-uses the template of its own place, with injection.
TEST(SequenceRecognitionTest, SecondLapInOtherLightReusesTheFirstLapsTemplates) {
  constexpr int kPlaces = 150;
  for (const bool recognise : {false, true}) {
    std::unique_ptr<FrontEnd> front_end = CreateFrontEnd(SequenceSettings(recognise));
    Random noise(3);
    int reused = 0;
    for (int lap = 0; lap < 2; ++lap) {
      for (int place = 0; place < kPlaces; ++place) {
        const double t = lap * kPlaces + place;
        auto d = front_end->OnImage(t, Place(place, lap, &noise));
        ASSERT_TRUE(d.ok()) << d.status().message();
        ASSERT_TRUE(d->has_value());
        const FrameDecision& f = **d;
        if (lap == 0) {
          ASSERT_TRUE(f.view.is_new) << place;
          ASSERT_EQ(f.view.template_id, static_cast<uint32_t>(place));
        } else if (!f.view.is_new) {
          EXPECT_TRUE(recognise) << "the classic camera alone matched place " << place;
          EXPECT_EQ(f.view.template_id, static_cast<uint32_t>(place));
          EXPECT_TRUE(f.view.allow_injection);
          ++reused;
        }
      }
    }
    // Sequences are full from the 10th frame (lines before the lap's start run through the
    // first lap's end, which can end earlier); recognition starts one frame later.
    if (recognise) {
      EXPECT_GE(reused, kPlaces - 10);
    } else {
      EXPECT_EQ(reused, 0);
    }
  }
}

// Black frames (a tunnel on each lap) give no view with sequence recognition: the classic camera
// alone matches the second lap's black frame to the first lap's, at the other end of the route.
TEST(SequenceRecognitionTest, BlackFramesGiveNoView) {
  const GrayImage black{64, 32, std::vector<uint8_t>(64 * 32, 2)};
  for (const bool recognise : {false, true}) {
    std::unique_ptr<FrontEnd> front_end = CreateFrontEnd(SequenceSettings(recognise));
    Random noise(3);
    std::vector<std::optional<FrameDecision>> black_decisions;
    for (int lap = 0; lap < 2; ++lap) {
      for (int place = 0; place < 100; ++place) {
        const bool tunnel = (lap == 0 && place == 20) || (lap == 1 && place == 80);
        auto d = front_end->OnImage(lap * 100 + place, tunnel ? black : Place(place, lap, &noise));
        ASSERT_TRUE(d.ok()) << d.status().message();
        if (tunnel) black_decisions.push_back(*d);
      }
    }
    ASSERT_EQ(black_decisions.size(), 2u);
    if (recognise) {
      EXPECT_FALSE(black_decisions[0].has_value());
      EXPECT_FALSE(black_decisions[1].has_value());
    } else {
      ASSERT_TRUE(black_decisions[0].has_value() && black_decisions[1].has_value());
      EXPECT_FALSE(black_decisions[1]->view.is_new);
      EXPECT_EQ(black_decisions[1]->view.template_id, black_decisions[0]->view.template_id);
    }
  }
}

// A run resumed from saved state decides every later frame as the unbroken run does; bytes it
// did not write are refused; and the option needs a front end that takes camera frames.
TEST(SequenceRecognitionTest, StateRoundTripsAndTheOptionNeedsACamera) {
  const FrontEndSettings settings = SequenceSettings(true);
  std::unique_ptr<FrontEnd> a = CreateFrontEnd(settings);
  std::unique_ptr<FrontEnd> b = CreateFrontEnd(settings);
  Random noise_a(5), noise_b(5);
  for (int i = 0; i < 190; ++i) {
    ASSERT_TRUE(a->OnImage(i, Place(i % 150, i / 150, &noise_a)).ok());
    Place(i % 150, i / 150, &noise_b);  // the same noise drawn
  }
  const std::string saved = a->EncodeState();
  ASSERT_TRUE(b->DecodeState(saved).ok());
  for (int i = 190; i < 300; ++i) {
    auto da = a->OnImage(i, Place(i % 150, i / 150, &noise_a));
    auto db = b->OnImage(i, Place(i % 150, i / 150, &noise_b));
    ASSERT_TRUE(da.ok() && db.ok());
    EXPECT_EQ((*da)->view.template_id, (*db)->view.template_id) << i;
    EXPECT_EQ((*da)->view.is_new, (*db)->view.is_new) << i;
  }
  std::unique_ptr<FrontEnd> c = CreateFrontEnd(settings);
  EXPECT_FALSE(c->DecodeState(saved.substr(0, saved.size() - 3)).ok());
  EXPECT_FALSE(c->DecodeState(saved + "x").ok());
  EXPECT_EQ(c->size(), 0u);
  // Damaged bytes (flipped, cut short) are refused or taken, never a crash; a refused state
  // leaves the front end as it was (here: the saved run's 150 templates).
  ASSERT_TRUE(c->DecodeState(saved).ok());
  const uint32_t templates = c->size();
  Random damage(17);
  for (int i = 0; i < 300; ++i) {
    std::string bytes = saved;
    for (int k = 0; k < 4; ++k) {
      bytes[damage.NextU64() % bytes.size()] = static_cast<char>(damage.NextU64() & 0xff);
    }
    if (i % 3 == 0) bytes.resize(damage.NextU64() % bytes.size());
    std::unique_ptr<FrontEnd> d = CreateFrontEnd(settings);
    ASSERT_TRUE(d->DecodeState(saved).ok());
    if (!d->DecodeState(bytes).ok()) {
      EXPECT_EQ(d->size(), templates) << i;
      EXPECT_EQ(d->EncodeState(), saved) << i;
    }
  }
}

}  // namespace
}  // namespace ratslam::fusion
