#include "fusion/fabmap/localiser.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/random.h"
#include "fusion/fabmap/synthetic_words.h"

namespace ratslam::fabmap {
namespace {

// Two floors with the same 60 visual places (perfect aliasing) but their own access points,
// one every 8 m along a 60 m corridor; nodes 1 m apart.
struct TwoFloors {
  SyntheticWordWorld words;
  VisualModel visual;
  std::vector<Observation> places;  // existing visual words per position (both floors)

  TwoFloors() {
    words.vocabulary_size = 600;
    words.mean_words_per_observation = 40;
    Random random(1);
    std::vector<Observation> training;
    for (int i = 0; i < 400; ++i)
      training.push_back(words.Observe(words.SamplePlace(&random), &random));
    visual.tree = *LearnChowLiuTree(training, words.vocabulary_size);
    for (int i = 0; i < 200; ++i) {
      visual.samples.push_back(words.Observe(words.SamplePlace(&random), &random));
    }
    for (int x = 0; x < 60; ++x) places.push_back(words.SamplePlace(&random));
  }
  std::vector<WifiReading> Scan(int floor, double x, Random* random) const {
    std::vector<WifiReading> scan;
    for (int k = 0; k < 8; ++k) {
      const double d = std::abs(x - 8.0 * k) + 1.0;
      const double rssi = -35.0 - 25.0 * std::log10(d) + random->Gaussian(0.0, 3.0);
      std::string bssid = "ap";  // built piecewise: GCC 12 warns falsely on chained +
      bssid += std::to_string(floor * 100 + k);
      if (rssi > -90.0) scan.push_back({bssid, rssi});
    }
    return scan;
  }
  MapNode Node(int floor, int x, Random* random) const {
    MapNode n;
    n.visual = words.Observe(places[x], random);
    n.wifi = Scan(floor, x, random);
    n.travelled_m = x;
    n.time_s = x;
    return n;
  }
};

struct Outcome {
  int floor_mistakes = 0, within_3_m = 0, rejected = 0;
};

Outcome RunMode(FabmapMode mode, int bins = 4) {
  TwoFloors world;
  Random random(2);
  std::vector<MapNode> map;
  for (int floor = 0; floor < 2; ++floor) {
    for (int x = 0; x < 60; ++x) map.push_back(world.Node(floor, x, &random));
  }
  LocaliserSettings settings;
  settings.localiser.mode = mode;
  settings.wifi_words.bins = bins;
  settings.visual_detector.p_observed_given_exists = 0.8;  // the world's detector
  settings.wifi_detector.p_observed_given_exists = 0.8;
  auto localiser = Localiser::Build(settings, &world.visual, map);
  EXPECT_TRUE(localiser.ok()) << localiser.status().message();
  Outcome outcome;
  for (int floor = 0; floor < 2; ++floor) {
    for (int x = 0; x < 60; x += 3) {
      const MapNode q = world.Node(floor, x, &random);
      const LocalisationResult r = (*localiser)->Localise({q.visual, q.wifi});
      if (r.best_place < 0) {
        ++outcome.rejected;
        continue;
      }
      const int matched_floor = static_cast<int>(r.best_place / 60);
      const int matched_x = static_cast<int>(r.best_place % 60);
      if (matched_floor != floor) {
        ++outcome.floor_mistakes;
      } else if (std::abs(matched_x - x) <= 3) {
        ++outcome.within_3_m;
      }
    }
  }
  return outcome;
}

TEST(LocaliserTest, FusionAvoidsTheFloorMistakesOfAliasedVision) {
  // 40 queries. Vision alone cannot tell the floors apart; every mode with Wi-Fi can.
  const Outcome vision = RunMode(FabmapMode::kVision);
  EXPECT_GE(vision.floor_mistakes, 10);
  EXPECT_GE(vision.floor_mistakes + vision.within_3_m, 36);  // right place, maybe wrong floor
  const Outcome wifi = RunMode(FabmapMode::kWifi);
  EXPECT_LE(wifi.floor_mistakes, 1);
  EXPECT_GE(wifi.within_3_m, 20);  // 8 access points, 3 dB noise: Wi-Fi alone is coarse
  // Early and late fusion weigh 8 Wi-Fi words against 40 visual ones: far fewer mistakes.
  for (FabmapMode mode : {FabmapMode::kEarly, FabmapMode::kLate}) {
    const Outcome fused = RunMode(mode);
    EXPECT_LE(fused.floor_mistakes, vision.floor_mistakes / 2) << ToString(mode);
    EXPECT_GE(fused.within_3_m, 30) << ToString(mode);
  }
  // Wi-Fi guided searches only the Wi-Fi candidates, all on the right floor.
  const Outcome guided = RunMode(FabmapMode::kWifiGuided);
  EXPECT_LE(guided.floor_mistakes, 1);
  EXPECT_GE(guided.within_3_m, 34);
  // Wi-Fi check turns vision's wrong-floor answers into rejections.
  const Outcome check = RunMode(FabmapMode::kWifiCheck);
  EXPECT_LE(check.floor_mistakes, 2);
  EXPECT_GE(check.rejected, 8);
}

TEST(LocaliserTest, WifiCandidatesAreBestFirstAndCapped) {
  TwoFloors world;
  Random random(3);
  std::vector<MapNode> map;
  for (int x = 0; x < 60; ++x) map.push_back(world.Node(0, x, &random));
  LocaliserSettings settings;
  settings.localiser.mode = FabmapMode::kWifiGuided;
  settings.localiser.max_candidates = 5;
  settings.wifi_words.bins = 8;
  auto localiser = Localiser::Build(settings, &world.visual, map);
  ASSERT_TRUE(localiser.ok());
  WifiVocabulary vocabulary(settings.wifi_words);
  for (const MapNode& n : map) vocabulary.AddAccessPoints(*n.wifi);
  const auto candidates =
      (*localiser)->WifiCandidates(vocabulary.Encode(world.Scan(0, 30, &random)));
  ASSERT_FALSE(candidates.empty());
  EXPECT_LE(candidates.size(), 5u);
  EXPECT_LE(std::abs(static_cast<int>(candidates.front()) - 30), 4);
}

TEST(LocaliserTest, ErrorsNameWhatIsMissing) {
  LocaliserSettings settings;
  settings.localiser.mode = FabmapMode::kEarly;
  const auto no_vocabulary = Localiser::Build(settings, nullptr, {});
  ASSERT_FALSE(no_vocabulary.ok());
  EXPECT_NE(no_vocabulary.status().message().find("visual vocabulary"), std::string::npos);
  settings.localiser.mode = FabmapMode::kWifi;
  const auto no_scans = Localiser::Build(settings, nullptr, {MapNode{}});
  ASSERT_FALSE(no_scans.ok());
  EXPECT_NE(no_scans.status().message().find("Wi-Fi"), std::string::npos);
  EXPECT_FALSE(FabmapModeFromString("earley").ok());
  EXPECT_EQ(FabmapModeFromString("wifi_check").value(), FabmapMode::kWifiCheck);
  std::string error;
  EXPECT_TRUE(LocaliserOptions{}.IsValid(&error));
}

}  // namespace
}  // namespace ratslam::fabmap
