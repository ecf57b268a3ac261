// `ratslam wifi-map`, `ratslam locate` and `ratslam call`: the command lines, outputs and figures
// of the sessions that build Gaussian-process Wi-Fi maps, locate a phone in them and call the
// robot to it (Kudo and Miura; session/wifi_map_session.h, locate_session.h, call_session.h).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "apps/cli.h"
#include "apps/progress.h"
#include "common/number_text.h"
#include "common/output_folder.h"
#include "common/output_guard.h"
#include "io/config.h"
#include "io/provenance_json.h"
#include "phone/wifi_gp_map.h"
#include "render/renderer.h"
#include "session/call_session.h"
#include "session/locate_session.h"
#include "session/wifi_map_session.h"
#include "viewer/figures.h"
#include "viewer/localisation_figure.h"

namespace ratslam::apps {
namespace {

namespace fs = std::filesystem;

std::optional<phone::LocateOptions> LoadLocateOptions(const Arguments& args, const char* command) {
  if (!args.values.count("--config")) return phone::LocateOptions();
  StatusOr<phone::LocateOptions> o = io::LoadLocateConfigFile(args.values.at("--config"));
  if (!o.ok()) {
    std::cerr << "ratslam " << command << ": " << o.status().message() << "\n";
    return std::nullopt;
  }
  return *o;
}

// "2.3 m": a JSON number in metres to a tenth, for the terminal.
std::string Metres(const nlohmann::ordered_json& value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f m", value.is_number() ? value.get<double>() : NAN);
  return text;
}

// The session's SetUpPhone with the command's options, map and log.
StatusOr<session::PhoneSetup> SetUpPhone(const Arguments& args, const char* command) {
  const std::optional<phone::LocateOptions> options = LoadLocateOptions(args, command);
  if (!options) return Status::Error("");  // already reported
  return session::SetUpPhone(*options, args.values.at("--wifi-map"), args.values.at("--data"),
                             args.lenient);
}

}  // namespace

int WifiMapCommand(const Arguments& parsed) {
  const Arguments* args = &parsed;
  const std::optional<phone::LocateOptions> options = LoadLocateOptions(*args, "wifi-map");
  if (!options) return kExitError;
  auto fail = [](const Status& s) {
    std::cerr << MessagePrefix() << s.message() << "\n";
    return kExitError;
  };
  // Refused before any work: a Wi-Fi map is not replaced without --overwrite.
  if (Status s = CheckReplaceable(args->values.at("--out"), args->values.count("--overwrite") > 0,
                                  "--out");
      !s.ok()) {
    return fail(s);
  }
  const auto start = std::chrono::steady_clock::now();
  session::WifiMapInput input;
  input.data = args->all.at("--data");
  if (args->values.count("--run")) input.run = args->values.at("--run");
  input.lenient = args->lenient;
  StatusOr<session::BuiltWifiMap> built =
      session::BuildWifiMap(*options, input, args->values.at("--out"));
  if (!built.ok()) return fail(built.status());
  const phone::WifiGpMap* map = &built->map;
  const bool from_run = input.run.has_value();
  const fs::path out = args->values.at("--out");
  StatusOr<std::unique_ptr<DiskFolder>> folder =
      DiskFolder::Open(out.has_parent_path() ? out.parent_path().string() : ".");
  if (!folder.ok()) return fail(folder.status());
  Status written = folder.value()->Write(out.filename().string(), map->Encode());
  if (!written.ok()) return fail(written);
  nlohmann::ordered_json& j = built->summary;
  j["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  j["run"] = io::RunObject(args->Provenance(), args->all.at("--data"), std::nullopt, 0);
  char human[256];
  std::snprintf(human, sizeof human,
                "%swrote %s: %zu access points on %zu floor(s), %zu stored cells, from %zu "
                "samples (%s)\n",
                MessagePrefix().c_str(), out.string().c_str(), map->bssids().size(),
                map->floors().size(), static_cast<size_t>(map->stored_cells()), built->samples,
                from_run ? "run trajectory" : "ground truth");
  PrintOutcome(args->values.count("--json") > 0, args->quiet, j.dump(2) + "\n", human);
  return kExitOk;
}

int LocateCommand(const Arguments& parsed) {
  const Arguments* args = &parsed;
  auto fail = [](const Status& s) {
    if (!s.message().empty()) std::cerr << MessagePrefix() << s.message() << "\n";
    return kExitError;
  };
  StatusOr<session::PhoneSetup> setup = SetUpPhone(*args, "locate");
  if (!setup.ok()) return fail(setup.status());
  const std::string map_path = args->values.at("--wifi-map");
  const phone::LocateOptions* options = &setup->options;
  const dataset::Dataset& d = setup->data;
  StatusOr<session::LocateResult> located =
      session::Locate(*setup, args->values.at("--data"), map_path);
  if (!located.ok()) return fail(located.status());
  const std::vector<double>& filter_errors = located->filter_errors_m;
  const std::vector<double>& knn_errors = located->knn_errors_m;
  nlohmann::ordered_json& j = located->summary;
  j["run"] =
      io::RunObject(args->Provenance(), {args->values.at("--wifi-map"), args->values.at("--data")},
                    std::nullopt, 0);
  const std::string summary = j.dump(2) + "\n";
  StatusOr<std::unique_ptr<DiskFolder>> folder = DiskFolder::Open(args->values.at("--out"));
  if (!folder.ok()) return fail(folder.status());
  Status written = folder.value()->Write({{"config.toml", io::PrintLocateConfig(*options)},
                                          {"trajectory_tum.txt", located->TrajectoryTum()},
                                          {"errors.csv", located->ErrorsCsv()},
                                          {"candidates.csv", located->CandidatesCsv()},
                                          {"summary.json", summary}});
  if (!written.ok()) return fail(written);
  if (!filter_errors.empty()) {
    // The paper's fig. 16: the share of scans located within d, beside the 3-NN baseline.
    const std::vector<viewer::LocalisationCurve> curves = {
        {"particle filter (" + ToString(options->particle_filter.likelihood) + ")", filter_errors},
        {"weighted 3-NN fingerprints", knn_errors}};
    const std::string title =
        d.name + ": " + std::to_string(filter_errors.size()) + " scans with ground truth";
    Status drawn = WriteCommandFigure(
        *args, folder.value()->Path("cumulative_error.png"),
        [&](int w) {
          return viewer::LocalisationCurvesScene(curves, title,
                                                 viewer::LocalisationAxisEndM(curves), w);
        },
        render::kTwoColumnMm);
    if (!drawn.ok()) return fail(drawn);
  }
  std::string human = MessagePrefix() + std::to_string(d.wifi.size()) + " scans";
  if (!filter_errors.empty()) {
    const nlohmann::ordered_json f = session::LocationErrorSummary(filter_errors);
    const nlohmann::ordered_json k = session::LocationErrorSummary(knn_errors);
    human += ", " + std::to_string(filter_errors.size()) + " with ground truth";
    if (f.contains("median_error_m")) {
      human += ": median error " + Metres(f["median_error_m"]) + ", 90 % within " +
               Metres(f["p90_error_m"]);
    }
    if (k.contains("median_error_m")) {
      human += " (3-NN fingerprints: median " + Metres(k["median_error_m"]) + ", 90 % within " +
               Metres(k["p90_error_m"]) + ")";
    }
    human += "; " + f["wrong_floor"].dump() + " on the wrong floor";
  }
  human += "\n" + MessagePrefix() + "outputs in " + args->Shown(args->values.at("--out")) +
           " (summary.json; --json prints it here)\n";
  PrintOutcome(args->values.count("--json") > 0, args->quiet, summary, human);
  return kExitOk;
}

int CallCommand(const Arguments& parsed) {
  const Arguments* args = &parsed;
  auto fail = [](const Status& s) {
    if (!s.message().empty()) std::cerr << MessagePrefix() << s.message() << "\n";
    return kExitError;
  };
  const double at = args->Number("--at");
  StatusOr<session::RobotMap> robot = session::LoadRobotMap(args->values.at("--map"));
  if (!robot.ok()) return fail(robot.status());
  StatusOr<session::PhoneSetup> setup = SetUpPhone(*args, "call");
  if (!setup.ok()) return fail(setup.status());
  if (!setup->map.truth_from_map() && !args->quiet) {
    std::cerr << MessagePrefix() << "note: " << args->values.at("--wifi-map")
              << " was made from ground truth, not from a run: its frame is the robot map's "
                 "only if the map was drawn in the truth's frame (make it with wifi-map --run)\n";
  }
  StatusOr<session::CallResult> call = session::CallRobot(
      *setup, *robot, at,
      {args->values.at("--data"), args->values.at("--map"), args->values.at("--wifi-map")});
  if (!call.ok()) return fail(call.status());
  const phone::CallPlan* plan = &call->plan;
  const phone::RouteGraph& graph = call->graph;
  const phone::LocationEstimate& estimate = call->estimate;
  const std::optional<Point2>& truth_on_map = call->truth_on_map;
  const std::vector<std::pair<Point2, double>>& candidates = call->candidates;
  nlohmann::ordered_json& j = call->summary;

  // The figure: the experience map, the particles, the estimate, the truth, the candidates
  // (numbered by rank) and the robot's route.
  viewer::ExperienceMapImageData image;
  image.experiences = robot->experiences;
  image.links = robot->links;
  image.current = robot->current;
  viewer::ExperienceMapImageOptions options;
  viewer::WorldBounds b{graph.nodes[0].x, graph.nodes[0].y, graph.nodes[0].x, graph.nodes[0].y};
  auto grow = [&](const Point2& p) {
    b.min_x_m = std::min(b.min_x_m, p.x - 2);
    b.max_x_m = std::max(b.max_x_m, p.x + 2);
    b.min_y_m = std::min(b.min_y_m, p.y - 2);
    b.max_y_m = std::max(b.max_y_m, p.y + 2);
  };
  for (const Point2& p : graph.nodes) grow(p);
  for (const auto& c : candidates) grow(c.first);
  options.bounds = b;
  const std::string route_m = ShortestNumber(std::round(plan->length_m * 10) / 10);
  const std::string stops = std::to_string(plan->stops.size());
  const std::string candidate_count = std::to_string(candidates.size());
  // Laid out at 1600 x 1200 for PNG, at the page's width for PDF and SVG (4:3 either way).
  auto build = [&](int width_px) {
    viewer::ExperienceMapImageOptions o = options;
    if (width_px > 0) {
      o.width_px = width_px;
      o.height_px = width_px * 3 / 4;
    }
    o.title = o.width_px >= 1000
                  ? "calling the robot at " + ShortestNumber(at) + " s: route " + route_m +
                        " m through " + stops + " stops for " + candidate_count + " candidates"
                  : "call at " + ShortestNumber(at) + " s: route " + route_m + " m, " + stops +
                        " stops, " + candidate_count + " candidates";
    viewer::WorldToImage to_image;
    render::Scene scene = viewer::ExperienceMapScene(image, o, &to_image);
    const std::vector<phone::Particle>& particles = call->particles;
    const size_t every = std::max<size_t>(1, particles.size() / 3000);
    for (size_t k = 0; k < particles.size(); k += every) {
      scene.Disc(to_image(particles[k].x_m, particles[k].y_m), 1.6f, {120, 120, 120, 110}, 6);
    }
    std::vector<render::ScenePoint> line;
    for (uint32_t e : plan->route) line.push_back(to_image(graph.nodes[e].x, graph.nodes[e].y));
    scene.Polyline(line, 6.0f, {148, 103, 189, 230});  // purple: red marks loop closures
    for (size_t k = 0; k < candidates.size(); ++k) {
      const render::ScenePoint c = to_image(candidates[k].first.x, candidates[k].first.y);
      const render::ScenePoint e =
          to_image(graph.nodes[plan->serving_node[k]].x, graph.nodes[plan->serving_node[k]].y);
      // Numbered by rank as call.json numbers them (0 first); two digits get a larger disc.
      const std::string rank = std::to_string(k);
      scene.Line(c, e, 1.5f, {255, 127, 14, 255});
      scene.Disc(c, rank.size() > 1 ? 12.0f : 9.0f, {255, 127, 14, 255}, 20);
      scene.Text({c.x, c.y + 4.5f}, rank, 13.0f, {255, 255, 255, 255}, render::TextAnchor::kCenter);
    }
    const render::ScenePoint est = to_image(estimate.x_m, estimate.y_m);
    scene.Ring(est, 10.0f, 14.0f, 0.0f, 6.2832f, {31, 119, 180, 255}, 24);
    if (truth_on_map) {
      const render::ScenePoint t = to_image(truth_on_map->x, truth_on_map->y);
      scene.Line({t.x - 10, t.y - 10}, {t.x + 10, t.y + 10}, 3.0f, {44, 160, 44, 255});
      scene.Line({t.x - 10, t.y + 10}, {t.x + 10, t.y - 10}, 3.0f, {44, 160, 44, 255});
    }
    const std::string particles_etc = "grey: particles   blue ring: estimate" +
                                      std::string(truth_on_map ? "   green x: truth" : "");
    if (o.width_px >= 1000) {
      scene.Text({20, 75},
                 "purple: robot route   orange: candidates (k-means, by weight)   " + particles_etc,
                 15.0f, viewer::kInk);
    } else {  // a narrow page: two shorter lines
      scene.Text({20, 70}, "purple: route   orange: candidates (k-means)", 15.0f, viewer::kInk);
      scene.Text({20, 90}, particles_etc, 15.0f, viewer::kInk);
    }
    return scene;
  };

  j["run"] = io::RunObject(
      args->Provenance(),
      {args->values.at("--map"), args->values.at("--wifi-map"), args->values.at("--data")},
      std::nullopt, 0);
  const std::string summary = j.dump(2) + "\n";
  StatusOr<std::unique_ptr<DiskFolder>> folder = DiskFolder::Open(args->values.at("--out"));
  if (!folder.ok()) return fail(folder.status());
  Status written = folder.value()->Write({{"config.toml", io::PrintLocateConfig(setup->options)},
                                          {"route.csv", call->RouteCsv()},
                                          {"call.json", summary}});
  if (!written.ok()) return fail(written);
  Status drawn =
      WriteCommandFigure(*args, folder.value()->Path("call.png"), build, render::kTwoColumnMm);
  if (!drawn.ok()) return fail(drawn);
  std::string human = MessagePrefix() + "robot at experience " + j["robot_experience"].dump() +
                      ": route " + Metres(j["route_length_m"]) + " through " +
                      std::to_string(plan->stops.size()) + " stops for " +
                      std::to_string(candidates.size()) + " candidates";
  if (j.contains("estimate_error_m")) {
    human += "; estimate " + Metres(j["estimate_error_m"]) + " from the truth, nearest candidate " +
             Metres(j["nearest_candidate_error_m"]);
  }
  human += "\n" + MessagePrefix() + "outputs in " + args->Shown(args->values.at("--out")) +
           " (call.json; --json prints it here)\n";
  PrintOutcome(args->values.count("--json") > 0, args->quiet, summary, human);
  return kExitOk;
}

}  // namespace ratslam::apps
