#include "session/wifi_map_session.h"

#include <cmath>
#include <filesystem>
#include <utility>

#include "common/file_util.h"
#include "common/geometry.h"
#include "dataset/dataset_loader.h"
#include "io/config.h"
#include "io/run_reader.h"
#include "session/locate_session.h"
#include "sim/world.h"

namespace ratslam::session {
namespace {

namespace fs = std::filesystem;

// The walls of the simulated worlds among `paths` (a replay folder holding the world.toml that
// `ratslam simulate` wrote), in the world's frame, which is the ground truth's.
StatusOr<std::vector<phone::WallSegment>> WallsOfData(const std::vector<std::string>& paths) {
  std::vector<phone::WallSegment> walls;
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
                      bool lenient, std::vector<phone::WifiMapSample>* samples, size_t* scans,
                      phone::WifiGpMap* frame_of) {
  const fs::path run = run_folder;
  StatusOr<io::RunFolder> folder = io::ReadRunFolder(run.string());
  if (!folder.ok()) return folder.status();
  StatusOr<fusion::PipelineOptions> config = io::LoadConfigFile((run / "config.toml").string());
  if (!config.ok()) return config.status();
  StatusOr<std::vector<GroundTruthRow>> trajectory =
      io::ReadTumTrajectory((run / "trajectory_tum.txt").string());
  if (!trajectory.ok()) return trajectory.status();
  dataset::PhoneLogOptions phone;
  phone.lenient = lenient;
  phone.pdr = config->pdr;
  StatusOr<dataset::Dataset> data = dataset::LoadSessions(paths, phone);
  if (!data.ok()) return data.status();
  if (!folder->dataset_name.empty() && folder->dataset_name != data->name) {
    return Status::Error(run.string() + ": the run replayed data set '" + folder->dataset_name +
                         "', not '" + data->name + "' (give --data as the replay did)");
  }
  for (const WifiScan& scan : data->wifi) {
    ++*scans;
    const auto pose = dataset::InterpolateGroundTruth(*trajectory, scan.time_s);
    if (!pose || scan.readings.empty()) continue;
    samples->push_back({{pose->x_m, pose->y_m}, 0, ScanReadings(scan)});
  }
  // The compass's offset: circular mean of map heading minus compass heading.
  double sum_sin = 0.0, sum_cos = 0.0;
  for (const CompassRow& c : data->compass) {
    const auto pose = dataset::InterpolateGroundTruth(*trajectory, c.time_s);
    if (!pose) continue;
    sum_sin += std::sin(pose->theta_rad - c.heading_rad);
    sum_cos += std::cos(pose->theta_rad - c.heading_rad);
  }
  if (sum_sin != 0.0 || sum_cos != 0.0)
    frame_of->set_compass_to_map_rad(std::atan2(sum_sin, sum_cos));
  std::vector<Point2> on_map, on_truth;
  for (const GroundTruthRow& p : *trajectory) {
    const auto truth = dataset::GroundTruthAt(*data, p.time_s);
    if (!truth) continue;
    on_map.push_back({p.x_m, p.y_m});
    on_truth.push_back({truth->x_m, truth->y_m});
  }
  frame_of->set_truth_from_map(AlignRigid2D(on_map, on_truth));
  return Status::Ok();
}

}  // namespace

StatusOr<BuiltWifiMap> BuildWifiMap(const phone::LocateOptions& options, const WifiMapInput& input,
                                    const std::string& map_label) {
  dataset::PhoneLogOptions phone;
  phone.lenient = input.lenient;
  phone.pdr = options.pdr;
  std::optional<std::pair<double, double>> origin;
  std::vector<phone::WifiMapSample> samples;
  size_t scans = 0;
  phone::WifiGpMap frame;  // carries the run's frame when a run is given
  const bool from_run = input.run.has_value();
  if (input.data.empty()) return Status::Error("a Wi-Fi map needs at least one data set");
  if (from_run) {
    Status got = SamplesFromRun(*input.run, input.data, input.lenient, &samples, &scans, &frame);
    if (!got.ok()) return got;
    // The geographic origin the replay's phone logs were read in (the first log's).
    StatusOr<std::vector<dataset::Dataset>> first =
        LoadInOneFrame({input.data.front()}, phone, &origin);
    if (!first.ok()) return first.status();
  } else {
    StatusOr<std::vector<dataset::Dataset>> data = LoadInOneFrame(input.data, phone, &origin);
    if (!data.ok()) return data.status();
    for (const dataset::Dataset& d : data.value()) {
      for (const WifiScan& scan : d.wifi) {
        ++scans;
        const auto truth = dataset::GroundTruthAt(d, scan.time_s);
        if (!truth || scan.readings.empty()) continue;
        samples.push_back({{truth->x_m, truth->y_m}, truth->floor, ScanReadings(scan)});
      }
    }
  }
  if (samples.empty()) {
    return Status::Error(
        std::to_string(scans) +
        (from_run ? " Wi-Fi scans and none within the run's trajectory: a Wi-Fi map needs positions"
                  : " Wi-Fi scans and none with ground truth at its time: a Wi-Fi map needs "
                    "positions"));
  }
  StatusOr<phone::WifiGpMap> map = phone::WifiGpMap::Build(samples, options.wifi_map);
  if (!map.ok()) return map.status();
  map->set_geo_reference_deg(origin);
  map->set_compass_to_map_rad(frame.compass_to_map_rad());
  map->set_truth_from_map(frame.truth_from_map());
  if (!from_run) {  // a run's frame is not the world's: its walls would not line up
    StatusOr<std::vector<phone::WallSegment>> walls = WallsOfData(input.data);
    if (!walls.ok()) return walls.status();
    map->set_walls(std::move(walls).value());
  }
  BuiltWifiMap built{std::move(map).value(), scans, samples.size(), {}};
  const phone::WifiGpMap& m = built.map;
  nlohmann::ordered_json& j = built.summary;
  j["wifi_map"] = map_label;
  j["scans"] = scans;
  j["samples"] = samples.size();
  j["access_points"] = m.bssids().size();
  j["floors"] = m.floors();
  j["stored_cells"] = m.stored_cells();
  j["positions_from"] = from_run ? "run trajectory" : "ground truth";
  j["length_scale_m"] = m.options().length_scale_m;
  j["signal_sigma_dbm"] = m.options().signal_sigma_dbm;
  j["noise_sigma_dbm"] = m.options().noise_sigma_dbm;
  if (const auto& fit = m.fit_report()) {
    j["hyperparameter_fit"] = {{"log_marginal_likelihood_before", fit->log_likelihood_before},
                               {"log_marginal_likelihood_after", fit->log_likelihood_after},
                               {"training_sets", fit->sets},
                               {"training_points", fit->points}};
  }
  j["walls"] = m.walls().size();
  if (from_run) {
    j["compass_to_map_rad"] = m.compass_to_map_rad();
    if (m.truth_from_map()) j["map_to_truth_rmse_m"] = m.truth_from_map()->rmse_m;
  }
  return built;
}

}  // namespace ratslam::session
