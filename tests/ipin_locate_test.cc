// Locating a phone in a Gaussian-process Wi-Fi map (Kudo and Miura, section IV) on real logs:
// `ratslam wifi-map` from repetitions 01 and 02 of IPIN 2023 Track 3 training route 22 (one
// phone), `ratslam locate` of repetition 03 (another phone) in it.
//
// Why these thresholds. Chance: a location drawn uniformly from the cells the map stores lies on
// average `chance_m` from the truth (computed below: 9.9 m). The paper's filter averaged about
// 13 m with instantaneous scans; we measured 1.95 m (median 1.6 m) here and 0.9-7.4 m over the
// six routes (scripts/ipin_locate_table.sh), and require a quarter of chance and at most 5 m. The
// same run's 3-NN fingerprint answer (4.9 m here) is the baseline the filter must beat on this
// route.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>

#include "common/text_file.h"
#include "dataset/csv.h"
#include "phone/wifi_gp_map.h"
#include "tests/documented_keys.h"
#include "tests/run_ratslam.h"
#include "tests/test_paths.h"

namespace ratslam {
namespace {
namespace fs = std::filesystem;
using e2e::Result;
using e2e::RunRatslam;

TEST(IpinLocateTest, AParticleFilterLocatesAnotherPhoneInTheWifiMap) {
  const fs::path data = fs::path(ratslam::test_paths::SharedDataDir()) / "ipin2023-t3";
  auto log = [&](const char* rep) {
    return data / (std::string("IPIN2023_T3_TrainingTrial22_repetition") + rep + ".txt");
  };
  for (const char* rep : {"01", "02", "03"}) {
    if (!fs::exists(log(rep))) GTEST_SKIP() << "missing " << log(rep);
  }
  const fs::path root =
      fs::temp_directory_path() / ("ratslam_locate_" + std::to_string(::getpid()));
  fs::create_directories(root);
  const fs::path map = root / "route22.wifimap";
  const Result built = RunRatslam("wifi-map --data " + log("01").string() + " --data " +
                                      log("02").string() + " --out " + map.string(),
                                  root);
  ASSERT_EQ(built.exit_code, 0) << built.err;
  const Result located = RunRatslam("locate --quiet --wifi-map " + map.string() + " --data " +
                                        log("03").string() + " --out " + (root / "o").string(),
                                    root);
  ASSERT_EQ(located.exit_code, 0) << located.err;
  std::ifstream in(root / "o" / "summary.json");
  const nlohmann::json s = nlohmann::json::parse(in);
  EXPECT_TRUE(e2e::UndocumentedKeys(s).empty())
      << "undocumented: " << e2e::Join(e2e::UndocumentedKeys(s));
  ASSERT_GT(s["count"].get<int>(), 30);
  EXPECT_EQ(s["wrong_floor"], 0);

  // Chance from the map and the ground truth in errors.csv.
  StatusOr<std::string> bytes = ReadRegularFile(map.string(), "Wi-Fi map", size_t{1} << 30);
  ASSERT_TRUE(bytes.ok());
  StatusOr<phone::WifiGpMap> wifi = phone::WifiGpMap::Decode(*bytes, map.string());
  ASSERT_TRUE(wifi.ok()) << wifi.status().message();
  ASSERT_EQ(wifi->floors().size(), 1u);
  const std::vector<Point2> cells = wifi->KnownCells(wifi->floors().front());
  ASSERT_FALSE(cells.empty());
  StatusOr<dataset::CsvTable> errors =
      dataset::CsvTable::Read((root / "o" / "errors.csv").string(),
                              {"time_s", "x_m", "y_m", "floor", "known_aps", "true_x_m", "true_y_m",
                               "true_floor", "error_m", "knn_error_m"});
  ASSERT_TRUE(errors.ok()) << errors.status().message();
  double chance = 0.0;
  size_t n = 0;
  for (size_t r = 0; r < errors->rows(); ++r) {
    StatusOr<double> x = errors->Number(r, "true_x_m"), y = errors->Number(r, "true_y_m");
    if (!x.ok() || !y.ok()) continue;  // a scan without ground truth
    double sum = 0.0;
    for (const Point2& c : cells) sum += std::hypot(c.x - *x, c.y - *y);
    chance += sum / cells.size();
    ++n;
  }
  ASSERT_EQ(n, s["count"].get<size_t>());
  chance /= n;
  const double mean = s["mean_error_m"];
  RecordProperty("chance_m", std::to_string(chance));
  RecordProperty("mean_error_m", std::to_string(mean));
  EXPECT_LT(mean, 0.25 * chance);
  EXPECT_LT(mean, 5.0);
  EXPECT_LT(mean, s["knn_baseline"]["mean_error_m"].get<double>());

  // Fig. 15 of the busiest AP; an AP the map does not know is an error.
  const Result drawn = RunRatslam(
      "render wifi-map --wifi-map " + map.string() + " --out " + (root / "ap.png").string(), root);
  EXPECT_EQ(drawn.exit_code, 0) << drawn.err;
  EXPECT_GT(fs::file_size(root / "ap.png"), 10000u);
  EXPECT_EQ(RunRatslam("render wifi-map --wifi-map " + map.string() + " --ap nope --out " +
                           (root / "no.png").string(),
                       root)
                .exit_code,
            1);

  // Bad input: a corrupt map names the file; a log with no Wi-Fi says so; data without ground
  // truth cannot make a map.
  std::ofstream(root / "bad.wifimap") << bytes->substr(0, bytes->size() / 2);
  const Result corrupt =
      RunRatslam("locate --wifi-map " + (root / "bad.wifimap").string() + " --data " +
                     log("03").string() + " --out " + (root / "x").string(),
                 root);
  EXPECT_EQ(corrupt.exit_code, 1);
  EXPECT_NE(corrupt.err.find("bad.wifimap"), std::string::npos) << corrupt.err;
  // The synthetic camera loop: odometry and images, no Wi-Fi.
  ASSERT_EQ(RunRatslam("synthesize --out " + (root / "empty").string(), root).exit_code, 0);
  const Result no_wifi =
      RunRatslam("locate --wifi-map " + map.string() + " --data " + (root / "empty").string() +
                     " --out " + (root / "y").string(),
                 root);
  EXPECT_EQ(no_wifi.exit_code, 1);
  EXPECT_NE(no_wifi.err.find("no Wi-Fi scan"), std::string::npos) << no_wifi.err;
  // Ten million particles would take most of an hour on this minute of walking: refused before
  // the filter starts, naming the key.
  std::ofstream(root / "many.toml") << "[particle_filter]\nparticles = 10000000\n";
  const Result many = RunRatslam("locate --config " + (root / "many.toml").string() +
                                     " --wifi-map " + map.string() + " --data " +
                                     log("03").string() + " --out " + (root / "m").string(),
                                 root, 120);
  EXPECT_EQ(many.exit_code, 1);
  EXPECT_NE(many.err.find("[particle_filter] particles = 10000000 would take about"),
            std::string::npos)
      << many.err;
  // A 1 cm grid cell (1e8 cells to fit here: minutes and a gigabyte) is refused up front too.
  std::ofstream(root / "fine.toml") << "[wifi_map]\ncell_size_m = 0.01\n";
  const Result fine =
      RunRatslam("wifi-map --config " + (root / "fine.toml").string() + " --data " +
                     log("01").string() + " --out " + (root / "fine.wifimap").string(),
                 root, 120);
  EXPECT_EQ(fine.exit_code, 1);
  EXPECT_NE(fine.err.find("[wifi_map] cell_size_m = 0.01 m would need up to"), std::string::npos)
      << fine.err;
  const Result no_truth = RunRatslam(
      "wifi-map --data " + (root / "empty").string() + " --out " + (root / "z.wifimap").string(),
      root);
  EXPECT_EQ(no_truth.exit_code, 1);
  fs::remove_all(root);
}

// A Wi-Fi map made from a RatSLAM run (its experience map's frame, not the truth's), the phone
// located in it, and the robot called along the run's experience graph. The route is checked
// against the run's own CSVs (independently of the planner): every candidate's experience is on
// it, consecutive experiences are linked, and its length is the sum of its segments.
TEST(IpinLocateTest, ARunsMapLocatesThePhoneAndTheRobotIsCalled) {
  const fs::path data = fs::path(ratslam::test_paths::SharedDataDir()) / "ipin2023-t3";
  auto log = [&](const char* rep) {
    return (data / (std::string("IPIN2023_T3_TrainingTrial22_repetition") + rep + ".txt")).string();
  };
  for (const char* rep : {"01", "02", "03"}) {
    if (!fs::exists(log(rep))) GTEST_SKIP() << "missing " << log(rep);
  }
  const fs::path root = fs::temp_directory_path() / ("ratslam_call_" + std::to_string(::getpid()));
  fs::create_directories(root);
  const std::string run = (root / "run").string(), map_file = (root / "run.map").string();
  const std::string both = " --data " + log("01") + " --data " + log("02");
  const Result replayed =
      RunRatslam("replay --quiet --config " + std::string(ratslam::test_paths::SourceDir()) +
                     "/configs/ipin2023-wifi-compass.toml" + both + " --out " + run +
                     " --save-map " + map_file,
                 root);
  ASSERT_EQ(replayed.exit_code, 0) << replayed.err;
  const std::string wifi = (root / "run.wifimap").string();
  const Result built = RunRatslam("wifi-map --run " + run + both + " --out " + wifi, root);
  ASSERT_EQ(built.exit_code, 0) << built.err;
  // The same run with other data is refused by name.
  const Result wrong =
      RunRatslam("wifi-map --run " + run + " --data " + log("03") + " --out x.wifimap", root);
  EXPECT_EQ(wrong.exit_code, 1);
  EXPECT_NE(wrong.err.find("the run replayed data set"), std::string::npos) << wrong.err;

  StatusOr<phone::WifiGpMap> w = phone::WifiGpMap::Load(wifi);
  ASSERT_TRUE(w.ok()) << w.status().message();
  ASSERT_TRUE(w->truth_from_map().has_value());
  const Result located = RunRatslam("locate --quiet --wifi-map " + wifi + " --data " + log("03") +
                                        " --out " + (root / "o").string(),
                                    root);
  ASSERT_EQ(located.exit_code, 0) << located.err;
  std::ifstream in(root / "o" / "summary.json");
  const nlohmann::json s = nlohmann::json::parse(in);
  EXPECT_TRUE(e2e::UndocumentedKeys(s).empty())
      << "undocumented: " << e2e::Join(e2e::UndocumentedKeys(s));
  EXPECT_TRUE(s["errors_after_map_alignment"].get<bool>());
  EXPECT_GT(fs::file_size(root / "o" / "cumulative_error.png"), 10000u);
  // Chance: a uniform draw over the map's cells, moved into the truth's frame.
  const auto& a = *w->truth_from_map();
  std::vector<Point2> cells;
  for (const Point2& c : w->KnownCells(0)) {
    cells.push_back(
        {std::cos(a.rotation_rad) * c.x - std::sin(a.rotation_rad) * c.y + a.translation_x_m,
         std::sin(a.rotation_rad) * c.x + std::cos(a.rotation_rad) * c.y + a.translation_y_m});
  }
  StatusOr<dataset::CsvTable> errors = dataset::CsvTable::Read(
      (root / "o" / "errors.csv").string(), {"time_s", "true_x_m", "true_y_m", "error_m"},
      {"x_m", "y_m", "floor", "known_aps", "true_floor", "knn_error_m"});
  ASSERT_TRUE(errors.ok()) << errors.status().message();
  double chance = 0.0;
  size_t n = 0;
  for (size_t r = 0; r < errors->rows(); ++r) {
    StatusOr<double> x = errors->Number(r, "true_x_m"), y = errors->Number(r, "true_y_m");
    if (!x.ok() || !y.ok()) continue;
    double sum = 0.0;
    for (const Point2& c : cells) sum += std::hypot(c.x - *x, c.y - *y);
    chance += sum / cells.size();
    ++n;
  }
  ASSERT_GT(n, 30u);
  chance /= n;
  const double mean = s["mean_error_m"];
  RecordProperty("run_map_chance_m", std::to_string(chance));
  RecordProperty("run_map_mean_error_m", std::to_string(mean));
  // Measured: 3.4 m against a chance of 10.5 m (2.1 m without sensor resetting, which helps on
  // the maps from ground truth; see particle_filter.h). The run's own map error (2.6 m from
  // the truth after alignment) is part of what is measured.
  EXPECT_LT(mean, 0.35 * chance);
  EXPECT_LT(mean, s["knn_baseline"]["mean_error_m"].get<double>());

  // Call the robot at 100 s, from the run folder and from the saved map: the same plan.
  auto call = [&](const std::string& robot_map, const std::string& out) {
    const Result called =
        RunRatslam("call --quiet --format png,pdf --map " + robot_map + " --wifi-map " + wifi +
                       " --data " + log("03") + " --at 100 --out " + (root / out).string(),
                   root);
    EXPECT_EQ(called.exit_code, 0) << called.err;
    std::ifstream in(root / out / "call.json");
    return nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  };
  const nlohmann::json c = call(run, "c");
  {
    // --json prints call.json on stdout despite --quiet; without either, a pipe gets it too.
    const std::string args =
        "call --map " + run + " --wifi-map " + wifi + " --data " + log("03") + " --at 100 --out ";
    const Result json = RunRatslam(args + (root / "c_json").string() + " --quiet --json", root);
    EXPECT_EQ(json.exit_code, 0) << json.err;
    EXPECT_EQ(json.out, e2e::Slurp(root / "c_json" / "call.json"));
    const Result quiet = RunRatslam(args + (root / "c_quiet").string() + " --quiet", root);
    EXPECT_EQ(quiet.out, "");
  }
  EXPECT_TRUE(e2e::UndocumentedKeys(c).empty())
      << "undocumented: " << e2e::Join(e2e::UndocumentedKeys(c));

  ASSERT_TRUE(c.is_object());
  EXPECT_GT(fs::file_size(root / "c" / "call.png"), 10000u);
  {
    std::ifstream pdf(root / "c" / "call.pdf", std::ios::binary);
    std::string magic(5, '\0');
    pdf.read(magic.data(), 5);
    EXPECT_EQ(magic, "%PDF-");
  }
  EXPECT_LT(c["nearest_candidate_error_m"].get<double>(), 0.3 * chance);
  StatusOr<dataset::CsvTable> ex =
      dataset::CsvTable::Read(run + "/experiences.csv", {"id", "x_m", "y_m"},
                              {"theta_rad", "template_id", "time_s", "pose_cell_x", "pose_cell_y",
                               "pose_cell_theta", "floor"});
  StatusOr<dataset::CsvTable> links = dataset::CsvTable::Read(
      run + "/links.csv", {"from_id", "to_id"},
      {"id", "distance_m", "heading_rad", "facing_rad", "duration_s", "loop_closure", "kind"});
  StatusOr<dataset::CsvTable> route =
      dataset::CsvTable::Read((root / "c" / "route.csv").string(), {"experience_id"},
                              {"step", "x_m", "y_m", "stop_of_candidates"});
  ASSERT_TRUE(ex.ok() && links.ok() && route.ok());
  std::set<std::pair<int, int>> linked;
  for (size_t r = 0; r < links->rows(); ++r) {
    const int f = static_cast<int>(*links->Number(r, "from_id"));
    const int t = static_cast<int>(*links->Number(r, "to_id"));
    linked.insert({f, t});
    linked.insert({t, f});
  }
  std::vector<int> path;
  for (size_t r = 0; r < route->rows(); ++r) {
    path.push_back(static_cast<int>(*route->Number(r, "experience_id")));
  }
  ASSERT_FALSE(path.empty());
  EXPECT_EQ(path.front(), c["robot_experience"].get<int>());
  double length = 0.0;
  for (size_t k = 1; k < path.size(); ++k) {
    EXPECT_TRUE(linked.count({path[k - 1], path[k]})) << path[k - 1] << "-" << path[k];
    const size_t p = static_cast<size_t>(path[k - 1]), q = static_cast<size_t>(path[k]);
    length += std::hypot(*ex->Number(p, "x_m") - *ex->Number(q, "x_m"),
                         *ex->Number(p, "y_m") - *ex->Number(q, "y_m"));
  }
  EXPECT_NEAR(length, c["route_length_m"].get<double>(), 1e-6);
  for (const auto& candidate : c["candidates"]) {
    EXPECT_NE(std::find(path.begin(), path.end(), candidate["experience"].get<int>()), path.end())
        << "candidate " << candidate["rank"] << " is not visited";
  }
  const nlohmann::json f = call(map_file, "f");
  ASSERT_TRUE(f.is_object());
  EXPECT_EQ(f["robot_experience"], c["robot_experience"]);
  EXPECT_NEAR(f["route_length_m"].get<double>(), c["route_length_m"].get<double>(), 1e-6);
  // Asking before the first scan says so.
  const Result early = RunRatslam("call --map " + run + " --wifi-map " + wifi + " --data " +
                                      log("03") + " --at -5 --out " + (root / "e").string(),
                                  root);
  EXPECT_EQ(early.exit_code, 1);
  EXPECT_NE(early.err.find("no Wi-Fi scan at or before"), std::string::npos) << early.err;
  fs::remove_all(root);
}

}  // namespace
}  // namespace ratslam
