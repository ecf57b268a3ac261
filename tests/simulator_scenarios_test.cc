// The papers' scenarios on the built-in simulated worlds: each test runs the relevant modes
// end to end (`ratslam simulate`, `replay`, `evaluate`) and checks the direction of the papers'
// findings, not their numbers. Margins leave room around the values measured when the test
// was written (in comments; docs/simulator.md's scenario table has them all).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tests/test_paths.h"

namespace {
namespace fs = std::filesystem;
using nlohmann::json;

class SimulatedScenarios : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = fs::temp_directory_path() / ("ratslam_scenarios_" + std::to_string(::getpid()));
    fs::create_directories(root_);
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }

  static std::string Read(const fs::path& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }
  // `text` with the first line starting with `key` replaced by `line` (std::regex trips GCC 12's
  // maybe-uninitialized warning in the sanitizer build).
  static std::string SetLine(std::string text, const std::string& key, const std::string& line) {
    size_t at = 0;
    while (at < text.size() && text.compare(at, key.size(), key) != 0) {
      at = text.find('\n', at);
      if (at == std::string::npos) return text;
      ++at;
    }
    if (at >= text.size()) return text;
    const size_t end = text.find('\n', at);
    return text.replace(at, end == std::string::npos ? std::string::npos : end - at, line);
  }
  static void Run(const std::string& command) {
    ASSERT_EQ(std::system((command + " > /dev/null").c_str()), 0) << command;
  }
  // The world simulated once per test binary run (seed 1).
  static fs::path World(const std::string& name) {
    const fs::path out = root_ / ("sim-" + name);
    if (!fs::exists(out / "manifest.toml")) {
      Run(std::string(ratslam::test_paths::RatslamBinary()) + " simulate --quiet --world " + name +
          " --out " + out.string());
    }
    return out;
  }
  // configs/sim-fused.toml with the [fused] sensor switches set.
  static json Replay(const std::string& world, bool camera, bool wifi, bool compass) {
    std::string text = Read(fs::path(ratslam::test_paths::SourceDir()) / "configs/sim-fused.toml");
    auto set = [&](const std::string& key, bool on) {
      text = SetLine(text, key + " =", key + (on ? " = true" : " = false"));
    };
    set("use_camera", camera);
    set("use_wifi", wifi);
    set("use_compass", compass);
    const std::string tag =
        world + "-" + std::to_string(camera) + std::to_string(wifi) + std::to_string(compass);
    const fs::path config = root_ / (tag + ".toml");
    std::ofstream(config) << text;
    const fs::path out = root_ / ("replay-" + tag);
    Run(std::string(ratslam::test_paths::RatslamBinary()) + " replay --quiet --config " +
        config.string() + " --data " + World(world).string() + " --out " + out.string());
    return json::parse(Read(out / "summary.json"));
  }
  // configs/sim-fabmap.toml in `mode`, the vocabulary learnt once from the office's images.
  static json Evaluate(const std::string& world, const std::string& mode) {
    std::string text = Read(fs::path(ratslam::test_paths::SourceDir()) / "configs/sim-fabmap.toml");
    text = SetLine(text, "mode =", "mode = \"" + mode + "\"");
    const fs::path model = root_ / "visual_model.bin";
    if (fs::exists(model)) {
      text = SetLine(text, "training_images =", "file = \"" + model.string() + "\"");
    } else {
      text = SetLine(text, "training_images =",
                     "training_images = \"" + (World("office") / "images").string() + "\"");
    }
    const fs::path config = root_ / ("fabmap-" + world + "-" + mode + ".toml");
    std::ofstream(config) << text;
    const fs::path out = root_ / ("evaluate-" + world + "-" + mode);
    const fs::path data = World(world);
    Run(std::string(ratslam::test_paths::RatslamBinary()) + " evaluate --quiet --config " +
        config.string() + " --map " + data.string() + " --query " + data.string() + " --out " +
        out.string());
    if (!fs::exists(model) && fs::exists(out / "visual_model.bin")) {
      fs::copy_file(out / "visual_model.bin", model);
    }
    return json::parse(Read(out / "evaluation.json"));
  }
  static double Within5(const json& summary) {
    return summary["matches"].get<int>() > 0 ? summary["match_rate_within_m"]["5"].get<double>()
                                             : 0.0;
  }

  static fs::path root_;
};
fs::path SimulatedScenarios::root_;

// Wi-Fi RatSLAM paper: on a circular route reversed half way, Wi-Fi matches made in the other
// direction inject the old heading; the compass keeps it right. Measured: map ATE 12.0 m (Wi-Fi)
// against 1.87 m (Wi-Fi + compass); dead reckoning 3.0 m.
TEST_F(SimulatedScenarios, CircularBuildingCompassFixesTheReversal) {
  const json wifi = Replay("circular", false, true, false);
  const json wifi_compass = Replay("circular", false, true, true);
  EXPECT_LT(wifi_compass["map_ate_m"].get<double>(), 0.75 * wifi["map_ate_m"].get<double>());
  EXPECT_GT(wifi["matches"].get<int>(), 50);
}

// Day then night around one loop. Measured: camera only 2 % of its matches within 5 m (113
// matches); Wi-Fi 77 % (78); fused 73 % (614); map ATE fused 1.74 m, the lowest with Wi-Fi +
// compass (1.74; camera + compass 10.6, Wi-Fi 5.35, camera 25.9, dead reckoning 25.9). FABMAP
// within 5 m: vision 9 %, Wi-Fi 5 %, early fusion 20 %.
TEST_F(SimulatedScenarios, DayNightWifiAndFusionBridgeTheLightingChange) {
  const json camera = Replay("day_night", true, false, false);
  const json wifi = Replay("day_night", false, true, false);
  const json fused = Replay("day_night", true, true, true);
  EXPECT_LT(Within5(camera), 0.15);
  EXPECT_GE(Within5(wifi), 0.6);
  EXPECT_GE(Within5(fused), 0.6);
  EXPECT_GT(fused["matches"].get<int>(), 4 * camera["matches"].get<int>() * Within5(camera) + 50);
  const double fused_ate = fused["map_ate_m"];
  for (const json* other : {&camera, &wifi}) {
    EXPECT_LT(fused_ate, (*other)["map_ate_m"].get<double>());
  }
  const json wifi_compass = Replay("day_night", false, true, true);
  const json camera_compass = Replay("day_night", true, false, true);
  EXPECT_LT(fused_ate, 1.05 * wifi_compass["map_ate_m"].get<double>());
  EXPECT_LT(fused_ate, camera_compass["map_ate_m"].get<double>());

  const json vision = Evaluate("day_night", "vision");
  const json early = Evaluate("day_night", "early");
  EXPECT_GT(early["correct_within_m"]["5"].get<double>(),
            vision["correct_within_m"]["5"].get<double>() + 0.05);
}

// Two floors that look the same, with their own access points. Measured: RatSLAM camera only
// 644 matches to the other floor, Wi-Fi 0, fused 118; FABMAP floor mistakes: vision 39 %,
// early 28 %, Wi-Fi guided 5.4 %, Wi-Fi check 0.4 %.
TEST_F(SimulatedScenarios, AliasedFloorsWifiPreventsFloorMistakes) {
  const json camera = Replay("aliased_floors", true, false, false);
  const json wifi = Replay("aliased_floors", false, true, false);
  const json fused = Replay("aliased_floors", true, true, true);
  EXPECT_GT(camera["floor_mistakes"].get<int>(), 200);
  EXPECT_LE(wifi["floor_mistakes"].get<int>(), 5);
  // A match to the other floor is a miss at every d, even where the floors lie on top of each
  // other (they once counted as within 20 m here).
  EXPECT_LE(camera["match_rate_within_m"]["20"].get<double>(),
            1.0 - camera["floor_mistakes"].get<double>() / camera["matches"].get<double>() + 1e-12);
  EXPECT_LT(fused["floor_mistakes"].get<int>(), camera["floor_mistakes"].get<int>() / 3);

  const double vision = Evaluate("aliased_floors", "vision")["floor_mistake_rate"];
  EXPECT_GT(vision, 0.2);
  EXPECT_LT(Evaluate("aliased_floors", "early")["floor_mistake_rate"].get<double>(), vision);
  EXPECT_LT(Evaluate("aliased_floors", "wifi_guided")["floor_mistake_rate"].get<double>(),
            vision / 3);
  EXPECT_LT(Evaluate("aliased_floors", "wifi_check")["floor_mistake_rate"].get<double>(), 0.05);
}

// A small apartment where vision already works: adding Wi-Fi (early fusion) does not make it
// worse. Measured within 5 m: vision 100 %, early 100 %.
TEST_F(SimulatedScenarios, ApartmentEarlyFusionIsNoWorseThanVision) {
#if defined(__SANITIZE_ADDRESS__)
  // In the sanitizer suite the `evaluate` this runs ends with LeakSanitizer's own tracer crashing
  // at exit ("Tracer caught signal 11", twice in a row in CI, with llvmpipe's
  // threads and Mesa's shader cache already off; it passes alone). AddressSanitizer reports
  // nothing before that; the plain build runs this check.
  GTEST_SKIP() << "LeakSanitizer's tracer crashes at the exit of this evaluate run";
#endif
  const json vision = Evaluate("apartment", "vision");
  const json early = Evaluate("apartment", "early");
  EXPECT_GT(vision["correct_within_m"]["5"].get<double>(), 0.8);
  EXPECT_GE(early["correct_within_m"]["5"].get<double>(),
            vision["correct_within_m"]["5"].get<double>() - 0.02);
}

// The office corridor, up and down three times: the fused map beats dead reckoning (measured
// 0.59 m against 1.92 m).
TEST_F(SimulatedScenarios, OfficeCorridorFusedMapBeatsOdometry) {
  const json fused = Replay("office", true, true, true);
  EXPECT_LT(fused["map_ate_m"].get<double>(), fused["odometry_ate_m"].get<double>());
  EXPECT_GT(fused["loop_closures"].get<int>(), 5);
}

}  // namespace
