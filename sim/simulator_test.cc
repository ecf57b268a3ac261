#include "sim/simulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "sim/propagation.h"
#include "sim/textures.h"
#include "sim/world.h"
#include "tests/test_paths.h"

namespace ratslam::sim {
namespace {
namespace fs = std::filesystem;

// A 10 m x 4 m room with one access point and a short route.
const char kSmallWorld[] = R"(name = "small"
[camera]
width_px = 32
height_px = 24
rate_hz = 2.0
[wifi]
scan_period_s = 1.0
[[walls]]
from = [0.0, 0.0]
to = [10.0, 0.0]
texture = "posters:1"
[[walls]]
from = [10.0, 0.0]
to = [10.0, 4.0]
texture = "brick:2"
[[walls]]
from = [10.0, 4.0]
to = [0.0, 4.0]
texture = "stripes:3"
[[walls]]
from = [0.0, 4.0]
to = [0.0, 0.0]
material = "concrete"
texture = "door:4"
[[access_points]]
name = "ap-1"
position = [5.0, 2.0]
[[disturbances]]
position = [8.0, 2.0]
radius_m = 1.0
strength_deg = 40.0
[[routes]]
name = "r"
closed = true
points = [[1.0, 1.0, 0], [9.0, 1.0, 0], [9.0, 3.0, 0], [1.0, 3.0, 0]]
[[sessions]]
route = "r"
laps = 1.5
)";

World Small() {
  auto w = ParseWorld(kSmallWorld, "small.toml");
  EXPECT_TRUE(w.ok()) << w.status().message();
  return *w;
}

TEST(PropagationTest, FreeSpaceAndOneWallByHand) {
  World w = Small();
  w.walls = {w.walls[0]};           // one drywall along y = 0
  w.wifi.path_loss_exponent = 2.0;  // free space
  w.access_points[0].position = {0, 1};
  w.access_points[0].tx_power_dbm = 20.0;
  w.access_points[0].channel = 6;  // 2437 MHz
  const WifiPropagation p(w, 1);
  // FSPL(1 m, 2437 MHz) = 20 log10(2437) - 27.55 = 40.187 dB.
  EXPECT_NEAR(FreeSpaceLossDb(1.0, 2437.0), 40.187, 1e-3);
  EXPECT_NEAR(p.MeanPowerDbm(0, {1, 1}, 0, 0), 20.0 - 40.187, 1e-3);
  EXPECT_NEAR(p.MeanPowerDbm(0, {10, 1}, 0, 0), 20.0 - 60.187, 1e-3);
  // Through the wall (y = 0) at 10 m: 4 dB of drywall more.
  EXPECT_NEAR(p.MeanPowerDbm(0, {0, -9}, 0, 0), 20.0 - 60.187 - 4.0, 1e-3);
  EXPECT_NEAR(p.WallLossDb({0, 1}, {0, -9}, 0), 4.0, 1e-12);
  // A floor up: 15 dB per floor, and the walls of the other floor do not count.
  EXPECT_NEAR(p.MeanPowerDbm(0, {0, -9}, 1, 0), 20.0 - 60.187 - 15.0, 1e-3);
  // 5 GHz channel 36: 5180 MHz.
  EXPECT_DOUBLE_EQ(ChannelFrequencyMhz(36), 5180.0);
}

TEST(PropagationTest, AccessPointsSwitchedOffOrMovedBetweenSessions) {
  World w = Small();
  w.wifi.miss_probability = 0.0;
  w.wifi.fading_sigma_db = 0.0;
  AccessPoint second = w.access_points[0];
  second.name = "ap-2";
  second.off_in_sessions = {1};
  w.access_points[0].moved_in_sessions = {2};
  w.access_points[0].moved_to = {9.0, 2.0};
  w.access_points.push_back(second);
  const WifiPropagation p(w, 3);
  Random random(1);
  auto rssi_of = [&](int session, const std::string& name) {
    for (const WifiReading& r : p.Scan({1.0, 2.0}, 0, session, &random)) {
      if (r.bssid == name) return r.rssi_dbm;
    }
    return -999.0;
  };
  EXPECT_GT(rssi_of(0, "ap-2"), -90.0);
  EXPECT_EQ(rssi_of(1, "ap-2"), -999.0);  // off in session 1
  EXPECT_GT(rssi_of(2, "ap-2"), -90.0);
  // Moved from 4 m away to 8 m away in session 2: 10 n log10(2) = 9 dB weaker on average.
  EXPECT_NEAR(p.MeanPowerDbm(0, {1.0, 2.0}, 0, 0) - p.MeanPowerDbm(0, {1.0, 2.0}, 0, 2),
              30.0 * std::log10(2.0), 1e-9);
}

TEST(PropagationTest, ShadowingIsSpatiallyCorrelated) {
  World w = Small();
  w.wifi.shadowing_sigma_db = 6.0;
  w.wifi.shadowing_correlation_m = 3.0;
  const WifiPropagation p(w, 5);
  EXPECT_EQ(p.ShadowingDb(0, {2.3, 1.7}, 0), p.ShadowingDb(0, {2.3, 1.7}, 0));
  double sum = 0, sum_sq = 0, near_diff = 0, far_diff = 0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const Point2 a{0.37 * i, 0.11 * i};
    const double s = p.ShadowingDb(0, a, 0);
    sum += s;
    sum_sq += s * s;
    near_diff += std::abs(s - p.ShadowingDb(0, {a.x_m + 0.2, a.y_m}, 0));
    far_diff += std::abs(s - p.ShadowingDb(0, {a.x_m + 30.0, a.y_m}, 0));
  }
  EXPECT_NEAR(std::sqrt(sum_sq / n - (sum / n) * (sum / n)), 6.0, 0.6);
  EXPECT_LT(near_diff, 0.3 * far_diff);  // close places shadow alike, far ones independently
}

TEST(SimulatorTest, SameSeedSameBytes) {
  const World w = Small();
  auto renderer = render::CreateOsMesaViewRenderer();
  ASSERT_TRUE(renderer.ok()) << renderer.status().message();
  const fs::path base = fs::temp_directory_path() / ("ratslam_sim_" + std::to_string(::getpid()));
  std::string first_csvs;
  for (int run = 0; run < 3; ++run) {
    const fs::path folder = base / std::to_string(run);
    dataset::Dataset d;
    SimulationReport report;
    ASSERT_TRUE(
        Simulate(w, run < 2 ? 7 : 8, renderer->get(), (folder / "images").string(), &d, &report)
            .ok());
    ASSERT_TRUE(dataset::WriteDataset(d, folder.string()).ok());
    EXPECT_GT(report.images, 10u);
    EXPECT_GT(report.scans, 10u);
    std::string all;
    for (const char* f :
         {"odometry.csv", "wifi.csv", "compass.csv", "ground_truth.csv", "images.csv"}) {
      std::ifstream in(folder / f);
      all += std::string(std::istreambuf_iterator<char>(in), {});
    }
    for (const auto& image : d.images) {
      std::ifstream in(folder / "images" / image.file, std::ios::binary);
      all += std::string(std::istreambuf_iterator<char>(in), {});
    }
    if (run == 0) first_csvs = all;
    if (run == 1) {
      EXPECT_EQ(all, first_csvs);  // same seed: same bytes
    } else if (run == 2) {
      EXPECT_NE(all, first_csvs);  // another seed: other noise
    }
  }
  fs::remove_all(base);
}

TEST(SimulatorTest, AWallOfAKnownTextureFillsTheView) {
  World w = Small();
  auto renderer = render::CreateOsMesaViewRenderer();
  ASSERT_TRUE(renderer.ok());
  // Facing the east wall (brick:2) from 1 m away with a 60 degree field of view.
  TruePose pose;
  pose.x_m = 9.0;
  pose.y_m = 2.0;
  w.camera.horizontal_fov_deg = 60.0;
  const render::ViewMesh mesh = FloorMesh(w, 0, 0.0);
  auto view = (*renderer)->Render(mesh, CameraAt(w, pose), LightingOf(w, 0));
  ASSERT_TRUE(view.ok()) << view.status().message();
  const std::vector<uint8_t> texture = MakeTexture("brick:2", 64);
  // The east wall's normal is along x: shade 0.65 + 0.35 * 0.6 = 0.86.
  const double shade = 0.86;
  const double lo = *std::min_element(texture.begin(), texture.end()) * shade - 3;
  const double hi = *std::max_element(texture.begin(), texture.end()) * shade + 3;
  double mean = 0;
  for (uint8_t v : view->pixels) {
    EXPECT_GE(v, lo);
    EXPECT_LE(v, hi);
    mean += v;
  }
  mean /= view->pixels.size();
  double texture_mean = 0;
  for (uint8_t v : texture) texture_mean += v;
  texture_mean = texture_mean / texture.size() * shade;
  EXPECT_NEAR(mean, texture_mean, 12.0);
  // Turned around, the camera sees the west wall (door:4): a different picture.
  pose.heading_rad = M_PI;
  pose.x_m = 1.0;
  auto other = (*renderer)->Render(mesh, CameraAt(w, pose), LightingOf(w, 0));
  ASSERT_TRUE(other.ok());
  double difference = 0;
  for (size_t i = 0; i < other->pixels.size(); ++i)
    difference += std::abs(other->pixels[i] - view->pixels[i]);
  EXPECT_GT(difference / other->pixels.size(), 10.0);
}

TEST(SimulatorTest, TrajectoryFollowsTheRouteAndCompassFeelsDisturbances) {
  const World w = Small();
  const auto poses = TrueTrajectory(w, 0.1);
  ASSERT_FALSE(poses.empty());
  // 1.5 laps of a 20 m loop at 1 m/s plus 5 quarter turns at 1 rad/s.
  EXPECT_NEAR(poses.back().time_s, 30.0 + 5 * M_PI / 2, 0.2);
  EXPECT_NEAR(poses.back().x_m, 9.0, 1e-6);  // half way round: the opposite corner
  EXPECT_NEAR(poses.back().y_m, 3.0, 1e-6);
  for (const TruePose& p : poses) {
    EXPECT_GE(p.x_m, 1.0 - 1e-6);
    EXPECT_LE(p.x_m, 9.0 + 1e-6);
  }
  dataset::Dataset d;
  SimulationReport report;
  ASSERT_TRUE(Simulate(w, 3, nullptr, "", &d, &report).ok());
  EXPECT_TRUE(d.images.empty());
  // Near the disturbance (8, 2) the compass is off by up to 40 degrees; far away by noise only.
  double worst_near = 0, worst_far = 0;
  for (const CompassRow& c : d.compass) {
    const auto truth = dataset::InterpolateGroundTruth(d.ground_truth, c.time_s);
    ASSERT_TRUE(truth.has_value());
    const double error =
        std::abs(std::remainder(c.heading_rad - truth->theta_rad, 2 * M_PI)) * 180 / M_PI;
    const double r = std::hypot(truth->x_m - 8.0, truth->y_m - 2.0);
    (r > 3.0 ? worst_far : worst_near) = std::max(r > 3.0 ? worst_far : worst_near, error);
  }
  EXPECT_LT(worst_far, 10.0);
  EXPECT_GT(worst_near, 15.0);  // the route passes 1 m from the centre: 40 exp(-1/2) = 24 deg
}

// Sessions are named by what sets them apart: lighting, the route when several are walked,
// "reversed", and an ordinal among sessions that would otherwise share a name.
TEST(SimulatorTest, SessionsAreNamedByWhatSetsThemApart) {
  World w = Small();
  w.sessions.front().laps = 0.25;
  Session night = w.sessions.front();
  night.lighting = "night";
  Session back = w.sessions.front();
  back.reverse = true;
  w.sessions = {w.sessions.front(), night, w.sessions.front(), back};
  dataset::Dataset d;
  SimulationReport report;
  ASSERT_TRUE(Simulate(w, 3, nullptr, "", &d, &report).ok());
  ASSERT_EQ(d.session_start_times_s.size(), 4u);
  EXPECT_EQ(d.session_names,
            (std::vector<std::string>{"day, 1", "night", "day, 2", "day, reversed"}));
  Route other = w.routes.front();
  other.name = "short";
  w.routes.push_back(other);
  w.sessions = {w.sessions[0], w.sessions[1]};
  w.sessions[1].route = "short";
  ASSERT_TRUE(Simulate(w, 3, nullptr, "", &d, &report).ok());
  EXPECT_EQ(d.session_names, (std::vector<std::string>{"r, day", "short, night"}));
}

TEST(WorldTest, ErrorsNameTheLineAndRoundTrip) {
  auto unknown = ParseWorld(
      std::string(kSmallWorld) + "[[walls]]\nfrom = [0, 0]\nto = [1, 0]\ncolour = 3\n", "w.toml");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.status().message().find("w.toml:"), std::string::npos);
  EXPECT_NE(unknown.status().message().find("colour"), std::string::npos);
  auto material = ParseWorld(
      std::string(kSmallWorld) + "[[walls]]\nfrom = [0, 0]\nto = [1, 0]\nmaterial = \"cheese\"\n",
      "w.toml");
  ASSERT_FALSE(material.ok());
  EXPECT_NE(material.status().message().find("cheese"), std::string::npos);
  auto point = ParseWorld("[[walls]]\nfrom = [0]\n", "w.toml");
  ASSERT_FALSE(point.ok());
  EXPECT_NE(point.status().message().find("w.toml:2"), std::string::npos);
  EXPECT_FALSE(ParseWorld("name = ", "w.toml").ok());
  for (const std::string& name : BuiltInWorldNames()) {
    auto w = BuiltInWorld(name);
    ASSERT_TRUE(w.ok()) << name << ": " << w.status().message();
    const std::string text = PrintWorld(*w);
    auto back = ParseWorld(text, name + ".toml");
    ASSERT_TRUE(back.ok()) << back.status().message();
    EXPECT_EQ(PrintWorld(*back), text) << name;
  }
  EXPECT_FALSE(BuiltInWorld("castle").ok());
}

// The step budget adds the gap between sessions; it once multiplied by it, so a gap of 0 let any
// world through. 1000 laps of the apartment at 1 cm/s is far beyond ten million steps.
TEST(WorldTest, StepBudgetHoldsWithoutASessionGap) {
  World world = *BuiltInWorld("apartment");
  world.motion.session_gap_s = 0.0;
  ASSERT_TRUE(world.Validate().ok());
  world.motion.speed_m_per_s = 0.01;
  world.sessions.front().laps = 1000;
  const Status status = world.Validate();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("ten million"), std::string::npos) << status.message();
}

}  // namespace
}  // namespace ratslam::sim

namespace ratslam::sim {
namespace {

// Every key a world table declares (world.h) is named in that table's row of configs/README.md,
// and each rule holds for the built-in worlds.
TEST(WorldSchemaTest, ReadmeNamesEveryWorldKeyAndBuiltInWorldsKeepTheRules) {
  std::ifstream in(std::string(ratslam::test_paths::SourceDir()) + "/configs/README.md");
  ASSERT_TRUE(in);
  std::map<std::string, std::string> rows;  // "[camera]" or "[[walls]]" -> its README row
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("| `[", 0) != 0) continue;
    rows[line.substr(3, line.find('`', 3) - 3)] = line;
  }
  auto documented = [&](const std::string& table, auto item) {
    ASSERT_TRUE(rows.count(table)) << table << " has no row in configs/README.md";
    item.VisitFields([&](const char* key, auto&, const char*, const schema::Rule&) {
      EXPECT_NE(rows[table].find("`" + std::string(key) + "`"), std::string::npos)
          << table << " " << key << " is not in configs/README.md";
    });
  };
  documented("[[walls]]", Wall());
  documented("[[access_points]]", AccessPoint());
  documented("[[disturbances]]", Disturbance());
  documented("[[people]]", Person());
  documented("[[routes]]", Route());
  documented("[[sessions]]", Session());
  documented("[camera]", CameraSettings());
  documented("[wifi]", WifiSettings());
  documented("[compass]", CompassSettings());
  documented("[odometry]", OdometrySettings());
  documented("[motion]", MotionSettings());
  for (const std::string& name : BuiltInWorldNames()) {
    StatusOr<World> world = BuiltInWorld(name);
    ASSERT_TRUE(world.ok()) << name << ": " << world.status().message();
    EXPECT_TRUE(world->Validate().ok()) << name;
  }
}

// A rule broken in a world file is reported with its line and a dotted key that names the item.
TEST(WorldSchemaTest, RuleErrorsNameLineAndItem) {
  const std::string walls =
      "[[walls]]\nfrom = [0, 0]\nto = [1, 0]\n[[walls]]\nfrom = [0, 0]\nto = [0, 1]\nfloor = "
      "5000\n";
  StatusOr<World> w = ParseWorld(walls, "w.toml");
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.status().message(), "w.toml:7: walls[1].floor: must be in [-1000, 1000]");
  StatusOr<World> c = ParseWorld("[camera]\nrate_hz = 0\n", "w.toml");
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.status().message(), "w.toml:2: camera.rate_hz: must be in (0, 100]");
  World programmatic = *BuiltInWorld("office");
  programmatic.wifi.miss_probability = 1.0;
  EXPECT_EQ(programmatic.Validate().message(), "world: wifi.miss_probability: must be in [0, 1)");
}

}  // namespace
}  // namespace ratslam::sim
