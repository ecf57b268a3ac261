// `ratslam wifi-map` and `ratslam locate`: Gaussian-process Wi-Fi maps from data with ground
// truth, and a particle filter that locates a phone in them (Kudo and Miura, section IV).
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
#include "common/file_util.h"
#include "common/number_text.h"
#include "common/output_folder.h"
#include "common/output_guard.h"
#include "fusion/io/config.h"
#include "fusion/io/map_file.h"
#include "fusion/io/provenance_json.h"
#include "fusion/io/run_reader.h"
#include "fusion/phone_localisation/particle_filter.h"
#include "fusion/phone_localisation/robot_call.h"
#include "fusion/phone_localisation/wifi_gp_map.h"
#include "render/renderer.h"
#include "sensors/dataset/dataset_loader.h"
#include "session/locate_session.h"
#include "sim/world.h"
#include "viewer/figures.h"
#include "viewer/localisation_figure.h"

namespace ratslam {
namespace {

namespace fs = std::filesystem;

std::optional<LocateOptions> LoadLocateOptions(const Arguments& args, const char* command) {
  if (!args.values.count("--config")) return LocateOptions();
  StatusOr<LocateOptions> o = LoadLocateConfigFile(args.values.at("--config"));
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
StatusOr<PhoneSetup> SetUpPhone(const Arguments& args, const char* command) {
  const std::optional<LocateOptions> options = LoadLocateOptions(args, command);
  if (!options) return Status::Error("");  // already reported
  return SetUpPhone(*options, args.values.at("--wifi-map"), args.values.at("--data"), args.lenient);
}

// The walls of the simulated worlds among `paths` (a replay folder holding the world.toml that
// `ratslam simulate` wrote), in the world's frame, which is the ground truth's.
StatusOr<std::vector<WallSegment>> WallsOfData(const std::vector<std::string>& paths) {
  std::vector<WallSegment> walls;
  for (const std::string& path : paths) {
    const fs::path world = fs::path(path) / "world.toml";
    if (!IsDirectory(path) || !PathExists(world)) continue;
    StatusOr<sim::World> w = sim::LoadWorldFile(world.string());
    if (!w.ok()) return w.status();
    for (const sim::Wall& wall : w->walls) {
      walls.push_back({wall.floor, {wall.from.x_m, wall.from.y_m}, {wall.to.x_m, wall.to.y_m}});
    }
    break;  // one world: the sessions of a simulation share it
  }
  return walls;
}

// Samples from a replay's run folder: each scan of the run's data (loaded as the replay loaded
// it, so times agree) placed where the run's final map puts the robot at that time
// (trajectory_tum.txt); the map's frame is the run's. Also finds the compass's offset to that
// frame and, with ground truth, the map's alignment onto the truth.
Status SamplesFromRun(const std::string& run_folder, const std::vector<std::string>& paths,
                      bool lenient, std::vector<WifiMapSample>* samples, size_t* scans,
                      WifiGpMap* frame_of) {
  const fs::path run = run_folder;
  StatusOr<RunFolder> folder = ReadRunFolder(run.string());
  if (!folder.ok()) return folder.status();
  StatusOr<PipelineOptions> config = LoadConfigFile((run / "config.toml").string());
  if (!config.ok()) return config.status();
  StatusOr<std::vector<GroundTruthRow>> trajectory =
      ReadTumTrajectory((run / "trajectory_tum.txt").string());
  if (!trajectory.ok()) return trajectory.status();
  PhoneLogOptions phone;
  phone.lenient = lenient;
  phone.pdr = config->pdr;
  StatusOr<Dataset> data = LoadSessions(paths, phone);
  if (!data.ok()) return data.status();
  if (!folder->dataset_name.empty() && folder->dataset_name != data->name) {
    return Status::Error(run.string() + ": the run replayed data set '" + folder->dataset_name +
                         "', not '" + data->name + "' (give --data as the replay did)");
  }
  for (const WifiScan& scan : data->wifi) {
    ++*scans;
    const auto pose = InterpolateGroundTruth(*trajectory, scan.time_s);
    if (!pose || scan.readings.empty()) continue;
    samples->push_back({{pose->x_m, pose->y_m}, 0, ScanReadings(scan)});
  }
  // The compass's offset: circular mean of map heading minus compass heading.
  double sum_sin = 0.0, sum_cos = 0.0;
  for (const CompassRow& c : data->compass) {
    const auto pose = InterpolateGroundTruth(*trajectory, c.time_s);
    if (!pose) continue;
    sum_sin += std::sin(pose->theta_rad - c.heading_rad);
    sum_cos += std::cos(pose->theta_rad - c.heading_rad);
  }
  if (sum_sin != 0.0 || sum_cos != 0.0)
    frame_of->set_compass_to_map_rad(std::atan2(sum_sin, sum_cos));
  std::vector<Point2> on_map, on_truth;
  for (const GroundTruthRow& p : *trajectory) {
    const auto truth = GroundTruthAt(*data, p.time_s);
    if (!truth) continue;
    on_map.push_back({p.x_m, p.y_m});
    on_truth.push_back({truth->x_m, truth->y_m});
  }
  frame_of->set_truth_from_map(AlignRigid2D(on_map, on_truth));
  return Status::Ok();
}

}  // namespace

int WifiMapCommand(const Arguments& parsed) {
  const Arguments* args = &parsed;
  const std::optional<LocateOptions> options = LoadLocateOptions(*args, "wifi-map");
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
  PhoneLogOptions phone;
  phone.lenient = args->lenient;
  phone.pdr = options->pdr;
  std::optional<std::pair<double, double>> origin;
  std::vector<WifiMapSample> samples;
  size_t scans = 0;
  WifiGpMap frame;  // carries the run's frame when --run is given
  const bool from_run = args->values.count("--run") > 0;
  if (from_run) {
    Status got = SamplesFromRun(args->values.at("--run"), args->all.at("--data"), args->lenient,
                                &samples, &scans, &frame);
    if (!got.ok()) return fail(got);
    // The geographic origin the replay's phone logs were read in (the first log's).
    StatusOr<std::vector<Dataset>> first =
        LoadInOneFrame({args->all.at("--data").front()}, phone, &origin);
    if (!first.ok()) return fail(first.status());
  } else {
    StatusOr<std::vector<Dataset>> data = LoadInOneFrame(args->all.at("--data"), phone, &origin);
    if (!data.ok()) return fail(data.status());
    for (const Dataset& d : data.value()) {
      for (const WifiScan& scan : d.wifi) {
        ++scans;
        const auto truth = GroundTruthAt(d, scan.time_s);
        if (!truth || scan.readings.empty()) continue;
        samples.push_back({{truth->x_m, truth->y_m}, truth->floor, ScanReadings(scan)});
      }
    }
  }
  if (samples.empty()) {
    return fail(Status::Error(
        std::to_string(scans) +
        (from_run ? " Wi-Fi scans and none within the run's trajectory: a Wi-Fi map needs positions"
                  : " Wi-Fi scans and none with ground truth at its time: a Wi-Fi map needs "
                    "positions")));
  }
  StatusOr<WifiGpMap> map = WifiGpMap::Build(samples, options->wifi_map);
  if (!map.ok()) return fail(map.status());
  map->set_geo_reference_deg(origin);
  map->set_compass_to_map_rad(frame.compass_to_map_rad());
  map->set_truth_from_map(frame.truth_from_map());
  if (!from_run) {  // a run's frame is not the world's: its walls would not line up
    StatusOr<std::vector<WallSegment>> walls = WallsOfData(args->all.at("--data"));
    if (!walls.ok()) return fail(walls.status());
    map->set_walls(std::move(walls).value());
  }
  const fs::path out = args->values.at("--out");
  StatusOr<std::unique_ptr<DiskFolder>> folder =
      DiskFolder::Open(out.has_parent_path() ? out.parent_path().string() : ".");
  if (!folder.ok()) return fail(folder.status());
  Status written = folder.value()->Write(out.filename().string(), map->Encode());
  if (!written.ok()) return fail(written);
  nlohmann::ordered_json j;
  j["wifi_map"] = out.string();
  j["scans"] = scans;
  j["samples"] = samples.size();
  j["access_points"] = map->bssids().size();
  j["floors"] = map->floors();
  j["stored_cells"] = map->stored_cells();
  j["positions_from"] = from_run ? "run trajectory" : "ground truth";
  j["length_scale_m"] = map->options().length_scale_m;
  j["signal_sigma_dbm"] = map->options().signal_sigma_dbm;
  j["noise_sigma_dbm"] = map->options().noise_sigma_dbm;
  if (const auto& fit = map->fit_report()) {
    j["hyperparameter_fit"] = {{"log_marginal_likelihood_before", fit->log_likelihood_before},
                               {"log_marginal_likelihood_after", fit->log_likelihood_after},
                               {"training_sets", fit->sets},
                               {"training_points", fit->points}};
  }
  j["walls"] = map->walls().size();
  if (from_run) {
    j["compass_to_map_rad"] = map->compass_to_map_rad();
    if (map->truth_from_map()) j["map_to_truth_rmse_m"] = map->truth_from_map()->rmse_m;
  }
  j["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  j["run"] = RunObject(args->Provenance(), args->all.at("--data"), std::nullopt, 0);
  char human[256];
  std::snprintf(human, sizeof human,
                "%swrote %s: %zu access points on %zu floor(s), %zu stored cells, from %zu "
                "samples (%s)\n",
                MessagePrefix().c_str(), out.string().c_str(), map->bssids().size(),
                map->floors().size(), static_cast<size_t>(map->stored_cells()), samples.size(),
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
  StatusOr<PhoneSetup> setup = SetUpPhone(*args, "locate");
  if (!setup.ok()) return fail(setup.status());
  const std::string map_path = args->values.at("--wifi-map");
  const LocateOptions* options = &setup->options;
  const Dataset& d = setup->data;
  StatusOr<LocateResult> located = Locate(*setup, args->values.at("--data"), map_path);
  if (!located.ok()) return fail(located.status());
  const std::vector<double>& filter_errors = located->filter_errors_m;
  const std::vector<double>& knn_errors = located->knn_errors_m;
  nlohmann::ordered_json& j = located->summary;
  j["run"] = RunObject(args->Provenance(),
                       {args->values.at("--wifi-map"), args->values.at("--data")}, std::nullopt, 0);
  const std::string summary = j.dump(2) + "\n";
  StatusOr<std::unique_ptr<DiskFolder>> folder = DiskFolder::Open(args->values.at("--out"));
  if (!folder.ok()) return fail(folder.status());
  Status written = folder.value()->Write({{"config.toml", PrintLocateConfig(*options)},
                                          {"trajectory_tum.txt", located->TrajectoryTum()},
                                          {"errors.csv", located->ErrorsCsv()},
                                          {"candidates.csv", located->CandidatesCsv()},
                                          {"summary.json", summary}});
  if (!written.ok()) return fail(written);
  if (!filter_errors.empty()) {
    // The paper's fig. 16: the share of scans located within d, beside the 3-NN baseline.
    const std::vector<LocalisationCurve> curves = {
        {"particle filter (" + ToString(options->particle_filter.likelihood) + ")", filter_errors},
        {"weighted 3-NN fingerprints", knn_errors}};
    const std::string title =
        d.name + ": " + std::to_string(filter_errors.size()) + " scans with ground truth";
    Status drawn = WriteCommandFigure(
        *args, folder.value()->Path("cumulative_error.png"),
        [&](int w) {
          return LocalisationCurvesScene(curves, title, LocalisationAxisEndM(curves), w);
        },
        kTwoColumnMm);
    if (!drawn.ok()) return fail(drawn);
  }
  std::string human = MessagePrefix() + std::to_string(d.wifi.size()) + " scans";
  if (!filter_errors.empty()) {
    const nlohmann::ordered_json f = LocationErrorSummary(filter_errors);
    const nlohmann::ordered_json k = LocationErrorSummary(knn_errors);
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

StatusOr<RobotMap> LoadRobotMap(const std::string& path) {
  RobotMap m;
  if (IsDirectory(path)) {
    StatusOr<RunFolder> run = ReadRunFolder(path);
    if (!run.ok()) return run.status();
    m.experiences = std::move(run->experiences);
    m.links = std::move(run->links);
    m.current = run->current_experience;
    for (auto f = run->frames.rbegin(); f != run->frames.rend() && !m.current; ++f) {
      if (f->experience_id >= 0 && f->experience_id < static_cast<int64_t>(m.experiences.size())) {
        m.current = static_cast<uint32_t>(f->experience_id);
      }
    }
  } else {
    StatusOr<MapFile> map = LoadMapFile(path);
    if (!map.ok()) return map.status();
    const ExperienceMap::State& state = map->state.ratslam.experience_map;
    m.experiences = state.experiences;
    m.links = state.links;
    m.current = state.current;
  }
  if (m.experiences.empty()) return Status::Error(path + ": the map has no experience");
  if (!m.current) m.current = static_cast<uint32_t>(m.experiences.size() - 1);
  return m;
}

int CallCommand(const Arguments& parsed) {
  const Arguments* args = &parsed;
  auto fail = [](const Status& s) {
    if (!s.message().empty()) std::cerr << MessagePrefix() << s.message() << "\n";
    return kExitError;
  };
  const std::optional<double> at = ParseNumber("--at", args->values.at("--at"));
  if (!at) return kExitUsage;
  StatusOr<RobotMap> robot = LoadRobotMap(args->values.at("--map"));
  if (!robot.ok()) return fail(robot.status());
  StatusOr<PhoneSetup> setup = SetUpPhone(*args, "call");
  if (!setup.ok()) return fail(setup.status());
  const WifiGpMap& map = setup->map;
  const Dataset& d = setup->data;
  if (d.wifi.front().time_s > *at) {
    return fail(Status::Error(args->values.at("--data") + ": no Wi-Fi scan at or before --at " +
                              ShortestNumber(*at) + " s (the first is at " +
                              ShortestNumber(d.wifi.front().time_s) + " s)"));
  }
  if (!map.truth_from_map() && !args->quiet) {
    std::cerr << MessagePrefix() << "note: " << args->values.at("--wifi-map")
              << " was made from ground truth, not from a run: its frame is the robot map's "
                 "only if the map was drawn in the truth's frame (make it with wifi-map --run)\n";
  }
  ParticleFilter filter(map, setup->options.particle_filter);
  Status initialised = filter.Initialise(!d.compass.empty());
  if (!initialised.ok()) return fail(initialised);
  size_t scans = 0;
  double last_scan_s = 0.0;
  FilterPhoneLog(d, map, &filter, *at, [&](const WifiScan& scan, size_t) {
    ++scans;
    last_scan_s = scan.time_s;
  });
  const LocationEstimate estimate = filter.Estimate();
  const std::vector<std::pair<Point2, double>> found = filter.Candidates();
  std::vector<Point2> candidates;
  for (const auto& c : found) candidates.push_back(c.first);
  RouteGraph graph;
  for (const Experience& e : robot->experiences) graph.nodes.push_back({e.x_m, e.y_m});
  for (const Link& l : robot->links) graph.edges.push_back({l.from, l.to});
  StatusOr<CallPlan> plan = PlanCall(graph, *robot->current, candidates);
  if (!plan.ok()) return fail(plan.status());

  nlohmann::ordered_json j;
  j["data"] = args->values.at("--data");
  j["map"] = args->values.at("--map");
  j["wifi_map"] = args->values.at("--wifi-map");
  j["at_s"] = *at;
  j["scans_used"] = scans;
  j["last_scan_s"] = last_scan_s;
  j["robot_experience"] = *robot->current;
  j["estimate"] = {{"x_m", estimate.x_m}, {"y_m", estimate.y_m}, {"floor", estimate.floor}};
  const auto truth = GroundTruthAt(d, last_scan_s);
  std::optional<Point2> truth_on_map;
  if (truth) {
    truth_on_map = TruthToMap(map, {truth->x_m, truth->y_m});
    j["truth_on_map"] = {{"x_m", truth_on_map->x}, {"y_m", truth_on_map->y}};
    j["estimate_error_m"] =
        std::hypot(estimate.x_m - truth_on_map->x, estimate.y_m - truth_on_map->y);
    double nearest = std::numeric_limits<double>::infinity();
    for (const Point2& c : candidates) {
      nearest = std::min(nearest, std::hypot(c.x - truth_on_map->x, c.y - truth_on_map->y));
    }
    j["nearest_candidate_error_m"] = nearest;
  }
  nlohmann::ordered_json cs = nlohmann::ordered_json::array();
  for (size_t k = 0; k < found.size(); ++k) {
    cs.push_back({{"rank", k},
                  {"x_m", found[k].first.x},
                  {"y_m", found[k].first.y},
                  {"weight", found[k].second},
                  {"experience", plan->serving_node[k]},
                  {"distance_to_experience_m", plan->serving_distance_m[k]}});
  }
  j["candidates"] = cs;
  j["stops"] = plan->stops;
  j["tour"] = plan->exact ? "exact (Held-Karp)" : "nearest neighbour + 2-opt";
  j["route_experiences"] = plan->route.size();
  j["route_length_m"] = plan->length_m;
  std::ostringstream route;
  route << "step,experience_id,x_m,y_m,stop_of_candidates\n";
  size_t next_stop = 0;
  for (size_t k = 0; k < plan->route.size(); ++k) {
    const uint32_t e = plan->route[k];
    route << k << ',' << e << ',' << ShortestNumber(graph.nodes[e].x) << ','
          << ShortestNumber(graph.nodes[e].y) << ',';
    if (next_stop < plan->stops.size() && plan->stops[next_stop] == e) {
      for (size_t c = 0; c < plan->stop_candidates[next_stop].size(); ++c) {
        route << (c ? " " : "") << plan->stop_candidates[next_stop][c];
      }
      ++next_stop;
    }
    route << '\n';
  }

  // The figure: the experience map, the particles, the estimate, the truth, the candidates
  // (numbered by rank) and the robot's route.
  ExperienceMapImageData image;
  image.experiences = robot->experiences;
  image.links = robot->links;
  image.current = robot->current;
  ExperienceMapImageOptions options;
  WorldBounds b{graph.nodes[0].x, graph.nodes[0].y, graph.nodes[0].x, graph.nodes[0].y};
  auto grow = [&](const Point2& p) {
    b.min_x_m = std::min(b.min_x_m, p.x - 2);
    b.max_x_m = std::max(b.max_x_m, p.x + 2);
    b.min_y_m = std::min(b.min_y_m, p.y - 2);
    b.max_y_m = std::max(b.max_y_m, p.y + 2);
  };
  for (const Point2& p : graph.nodes) grow(p);
  for (const Point2& p : candidates) grow(p);
  options.bounds = b;
  const std::string route_m = ShortestNumber(std::round(plan->length_m * 10) / 10);
  const std::string stops = std::to_string(plan->stops.size());
  const std::string candidate_count = std::to_string(candidates.size());
  // Laid out at 1600 x 1200 for PNG, at the page's width for PDF and SVG (4:3 either way).
  auto build = [&](int width_px) {
    ExperienceMapImageOptions o = options;
    if (width_px > 0) {
      o.width_px = width_px;
      o.height_px = width_px * 3 / 4;
    }
    o.title = o.width_px >= 1000
                  ? "calling the robot at " + ShortestNumber(*at) + " s: route " + route_m +
                        " m through " + stops + " stops for " + candidate_count + " candidates"
                  : "call at " + ShortestNumber(*at) + " s: route " + route_m + " m, " + stops +
                        " stops, " + candidate_count + " candidates";
    WorldToImage to_image;
    Scene scene = ExperienceMapScene(image, o, &to_image);
    const auto& particles = filter.particles();
    const size_t every = std::max<size_t>(1, particles.size() / 3000);
    for (size_t k = 0; k < particles.size(); k += every) {
      scene.Disc(to_image(particles[k].x_m, particles[k].y_m), 1.6f, {120, 120, 120, 110}, 6);
    }
    std::vector<ScenePoint> line;
    for (uint32_t e : plan->route) line.push_back(to_image(graph.nodes[e].x, graph.nodes[e].y));
    scene.Polyline(line, 6.0f, {148, 103, 189, 230});  // purple: red marks loop closures
    for (size_t k = 0; k < candidates.size(); ++k) {
      const ScenePoint c = to_image(candidates[k].x, candidates[k].y);
      const ScenePoint e =
          to_image(graph.nodes[plan->serving_node[k]].x, graph.nodes[plan->serving_node[k]].y);
      // Numbered by rank as call.json numbers them (0 first); two digits get a larger disc.
      const std::string rank = std::to_string(k);
      scene.Line(c, e, 1.5f, {255, 127, 14, 255});
      scene.Disc(c, rank.size() > 1 ? 12.0f : 9.0f, {255, 127, 14, 255}, 20);
      scene.Text({c.x, c.y + 4.5f}, rank, 13.0f, {255, 255, 255, 255}, TextAnchor::kCenter);
    }
    const ScenePoint est = to_image(estimate.x_m, estimate.y_m);
    scene.Ring(est, 10.0f, 14.0f, 0.0f, 6.2832f, {31, 119, 180, 255}, 24);
    if (truth_on_map) {
      const ScenePoint t = to_image(truth_on_map->x, truth_on_map->y);
      scene.Line({t.x - 10, t.y - 10}, {t.x + 10, t.y + 10}, 3.0f, {44, 160, 44, 255});
      scene.Line({t.x - 10, t.y + 10}, {t.x + 10, t.y - 10}, 3.0f, {44, 160, 44, 255});
    }
    const std::string particles_etc = "grey: particles   blue ring: estimate" +
                                      std::string(truth_on_map ? "   green x: truth" : "");
    if (o.width_px >= 1000) {
      scene.Text({20, 75},
                 "purple: robot route   orange: candidates (k-means, by weight)   " + particles_etc,
                 15.0f, kInk);
    } else {  // a narrow page: two shorter lines
      scene.Text({20, 70}, "purple: route   orange: candidates (k-means)", 15.0f, kInk);
      scene.Text({20, 90}, particles_etc, 15.0f, kInk);
    }
    return scene;
  };

  j["run"] = RunObject(
      args->Provenance(),
      {args->values.at("--map"), args->values.at("--wifi-map"), args->values.at("--data")},
      std::nullopt, 0);
  const std::string summary = j.dump(2) + "\n";
  StatusOr<std::unique_ptr<DiskFolder>> folder = DiskFolder::Open(args->values.at("--out"));
  if (!folder.ok()) return fail(folder.status());
  Status written = folder.value()->Write({{"config.toml", PrintLocateConfig(setup->options)},
                                          {"route.csv", route.str()},
                                          {"call.json", summary}});
  if (!written.ok()) return fail(written);
  Status drawn = WriteCommandFigure(*args, folder.value()->Path("call.png"), build, kTwoColumnMm);
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

}  // namespace ratslam
