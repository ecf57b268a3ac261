// `ratslam wifi-map` and `ratslam locate`: Gaussian-process Wi-Fi maps from data with ground
// truth, and a particle filter that locates a phone in them (Kudo and Miura, section IV).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "apps/cli.h"
#include "common/number_text.h"
#include "common/output_folder.h"
#include "fusion/io/config.h"
#include "fusion/io/run_reader.h"
#include "fusion/phone_localisation/particle_filter.h"
#include "fusion/phone_localisation/wifi_gp_map.h"
#include "sensors/dataset/dataset_loader.h"
#include "sensors/dataset/ipin_log.h"
#include "session/evaluation_baselines.h"

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

// Loads data sets in one frame: IPIN logs share the first one's geographic origin (or the given
// one). Returns the origin used, if any log had one.
StatusOr<std::vector<Dataset>> LoadInOneFrame(const std::vector<std::string>& paths,
                                              PhoneLogOptions phone,
                                              std::optional<std::pair<double, double>>* origin) {
  if (*origin) phone.reference = GeoReference{(*origin)->first, (*origin)->second};
  std::vector<Dataset> out;
  for (const std::string& path : paths) {
    StatusOr<DatasetFormat> format = DetectDatasetFormat(path);
    if (!format.ok()) return format.status();
    if (format.value() == DatasetFormat::kIpinLog) {
      PhoneLogReport report;
      StatusOr<Dataset> d = ReadIpinLog(path, phone, &report);
      if (!d.ok()) return d.status();
      if (!phone.reference) {
        phone.reference = report.reference;
        *origin = std::make_pair(report.reference.latitude_deg, report.reference.longitude_deg);
      }
      out.push_back(std::move(d.value()));
    } else {
      StatusOr<Dataset> d = LoadDataset(path, phone);
      if (!d.ok()) return d.status();
      out.push_back(std::move(d.value()));
    }
  }
  return out;
}

std::vector<std::pair<std::string, double>> Readings(const WifiScan& scan) {
  std::vector<std::pair<std::string, double>> r;
  for (const WifiReading& w : scan.readings) r.emplace_back(w.bssid, w.rssi_dbm);
  return r;
}

// Percentiles of the errors on the right floor; a wrong floor (infinite error) is counted apart.
nlohmann::ordered_json ErrorSummary(std::vector<double> all) {
  nlohmann::ordered_json j;
  std::vector<double> errors;
  for (double e : all) {
    if (std::isfinite(e)) errors.push_back(e);
  }
  std::sort(errors.begin(), errors.end());
  j["count"] = errors.size();
  j["wrong_floor"] = all.size() - errors.size();
  if (errors.empty()) return j;
  auto at = [&](double q) {
    return errors[std::min(errors.size() - 1, static_cast<size_t>(q * (errors.size() - 1) + 0.5))];
  };
  double sum = 0.0;
  for (double e : errors) sum += e;
  j["mean_error_m"] = sum / errors.size();
  j["median_error_m"] = at(0.5);
  j["p75_error_m"] = at(0.75);
  j["p90_error_m"] = at(0.9);
  return j;
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
    samples->push_back({{pose->x_m, pose->y_m}, 0, Readings(scan)});
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
    const auto truth = InterpolateGroundTruth(data->ground_truth, p.time_s);
    if (!truth) continue;
    on_map.push_back({p.x_m, p.y_m});
    on_truth.push_back({truth->x_m, truth->y_m});
  }
  frame_of->set_truth_from_map(AlignRigid2D(on_map, on_truth));
  return Status::Ok();
}

}  // namespace

int WifiMapCommand(int argc, char** argv) {
  const auto args = ParseArguments(argc, argv, 2, {"--data", "--out", "--config", "--run"});
  if (!args || !args->all.count("--data") || !args->values.count("--out")) {
    std::cerr << "usage: ratslam wifi-map --data D [--data D2 ...] --out W [--config C] "
                 "[--lenient]\n"
                 "       ratslam wifi-map --run RUN_FOLDER --data D [--data D2 ...] --out W "
                 "[--config C]\n"
                 "  (--run: positions from the run's trajectory_tum.txt, in its map's frame; "
                 "--data as given to that replay)\n";
    return kExitUsage;
  }
  const std::optional<LocateOptions> options = LoadLocateOptions(*args, "wifi-map");
  if (!options) return kExitError;
  auto fail = [](const Status& s) {
    std::cerr << "ratslam wifi-map: " << s.message() << "\n";
    return kExitError;
  };
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
        const auto truth = InterpolateGroundTruth(d.ground_truth, scan.time_s);
        if (!truth || scan.readings.empty()) continue;
        samples.push_back({{truth->x_m, truth->y_m}, truth->floor, Readings(scan)});
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
  if (from_run) {
    j["compass_to_map_rad"] = map->compass_to_map_rad();
    if (map->truth_from_map()) j["map_to_truth_rmse_m"] = map->truth_from_map()->rmse_m;
  }
  j["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << j.dump(2) << "\n";
  return kExitOk;
}

int LocateCommand(int argc, char** argv) {
  const auto args = ParseArguments(argc, argv, 2, {"--wifi-map", "--data", "--out", "--config"});
  if (!args || !args->values.count("--wifi-map") || !args->values.count("--data") ||
      !args->values.count("--out")) {
    std::cerr << "usage: ratslam locate --wifi-map W --data PHONE_LOG --out O [--config C] "
                 "[--lenient] [--quiet]\n";
    return kExitUsage;
  }
  const std::optional<LocateOptions> options = LoadLocateOptions(*args, "locate");
  if (!options) return kExitError;
  auto fail = [](const Status& s) {
    std::cerr << "ratslam locate: " << s.message() << "\n";
    return kExitError;
  };
  const std::string map_path = args->values.at("--wifi-map");
  StatusOr<WifiGpMap> map = WifiGpMap::Load(map_path);
  if (!map.ok()) return fail(map.status());
  PhoneLogOptions phone;
  phone.lenient = args->lenient;
  phone.pdr = options->pdr;
  std::optional<std::pair<double, double>> origin = map->geo_reference_deg();
  StatusOr<std::vector<Dataset>> data = LoadInOneFrame({args->values.at("--data")}, phone, &origin);
  if (!data.ok()) return fail(data.status());
  const Dataset& d = data.value().front();
  if (d.wifi.empty()) {
    return fail(
        Status::Error(args->values.at("--data") + ": no Wi-Fi scan to locate the phone by"));
  }
  ParticleFilter filter(map.value(), options->particle_filter);
  const bool compass = !d.compass.empty();
  Status initialised = filter.Initialise(compass);
  if (!initialised.ok()) return fail(initialised);

  // Replay odometry (PDR steps), compass and scans in time order.
  std::ostringstream tum, errors, candidates;
  tum << "# timestamp tx ty tz qx qy qz qw (particle filter estimate at each Wi-Fi scan)\n";
  errors << "time_s,x_m,y_m,floor,known_aps,true_x_m,true_y_m,true_floor,error_m,"
            "knn_error_m\n";
  candidates << "time_s,rank,x_m,y_m,weight\n";
  std::vector<double> filter_errors, knn_errors;
  size_t unknown_scans = 0;
  std::optional<double> heading, last_time, last_odometry;
  double integrated_heading = 0.0;
  // Fingerprint baseline on the map's own training scans (weighted 3-NN, session/).
  std::vector<fabmap::EvaluationNode> map_nodes;
  for (const WifiMapSample& s : map->training_samples()) {
    fabmap::EvaluationNode n;
    n.x_m = s.position.x;
    n.y_m = s.position.y;
    n.floor = s.floor;
    std::vector<WifiReading> r;
    for (const auto& [b, v] : s.readings) r.push_back({b, v});
    n.wifi = r;
    map_nodes.push_back(std::move(n));
  }
  std::vector<fabmap::EvaluationNode> queries;
  for (const WifiScan& scan : d.wifi) {
    fabmap::EvaluationNode q;
    q.wifi = scan.readings;
    queries.push_back(std::move(q));
  }
  const std::vector<fabmap::Estimate> knn = KnnEstimates(map_nodes, queries);
  size_t scan_index = 0;
  for (const Event& e : MergeEvents(d)) {
    if (e.type == EventType::kCompass) {
      heading = d.compass[e.index].heading_rad;
    } else if (e.type == EventType::kOdometry) {
      const OdometryRow& row = d.odometry[e.index];
      const double dt = last_odometry ? row.time_s - *last_odometry : 0.0;
      last_odometry = row.time_s;
      integrated_heading += row.turn_rate_rad_per_s * dt;
      const double forward = row.forward_speed_m_per_s * dt;
      if (forward != 0.0) {
        filter.Step(forward,
                    compass && heading ? *heading + map->compass_to_map_rad() : integrated_heading);
      }
    } else if (e.type == EventType::kWifi) {
      const WifiScan& scan = d.wifi[e.index];
      if (d.odometry.empty() && last_time) filter.Diffuse(scan.time_s - *last_time);
      last_time = scan.time_s;
      const size_t known = filter.Update(Readings(scan));
      unknown_scans += known == 0;
      const LocationEstimate est = filter.Estimate();
      tum << ShortestNumber(scan.time_s) << ' ' << ShortestNumber(est.x_m) << ' '
          << ShortestNumber(est.y_m) << " 0 0 0 0 1\n";
      const auto found = filter.Candidates();
      for (size_t k = 0; k < found.size(); ++k) {
        candidates << ShortestNumber(scan.time_s) << ',' << k << ','
                   << ShortestNumber(found[k].first.x) << ',' << ShortestNumber(found[k].first.y)
                   << ',' << ShortestNumber(found[k].second) << '\n';
      }
      errors << ShortestNumber(scan.time_s) << ',' << ShortestNumber(est.x_m) << ','
             << ShortestNumber(est.y_m) << ',' << est.floor << ',' << known;
      const auto truth = InterpolateGroundTruth(d.ground_truth, scan.time_s);
      if (truth) {
        // A map made from a run is in the run's frame and has one floor: its estimates are
        // scored after its alignment onto the truth, on position alone.
        const auto& align = map->truth_from_map();
        auto to_truth = [&](double x, double y) {
          if (!align) return Point2{x, y};
          const double c = std::cos(align->rotation_rad), s = std::sin(align->rotation_rad);
          return Point2{c * x - s * y + align->translation_x_m,
                        s * x + c * y + align->translation_y_m};
        };
        auto floor_differs = [&](int floor) { return !align && floor != truth->floor; };
        const Point2 e = to_truth(est.x_m, est.y_m);
        const double error = floor_differs(est.floor)
                                 ? std::numeric_limits<double>::infinity()
                                 : std::hypot(e.x - truth->x_m, e.y - truth->y_m);
        filter_errors.push_back(error);
        const fabmap::Estimate& k = knn[scan_index];
        const Point2 ke = to_truth(k.x_m, k.y_m);
        const double knn_error = !k.located || floor_differs(k.floor)
                                     ? std::numeric_limits<double>::infinity()
                                     : std::hypot(ke.x - truth->x_m, ke.y - truth->y_m);
        knn_errors.push_back(knn_error);
        errors << ',' << ShortestNumber(truth->x_m) << ',' << ShortestNumber(truth->y_m) << ','
               << truth->floor << ',' << ShortestNumber(error) << ',' << ShortestNumber(knn_error)
               << '\n';
      } else {
        errors << ",,,,,\n";
      }
      ++scan_index;
    }
  }
  nlohmann::ordered_json j;
  j["data"] = args->values.at("--data");
  j["wifi_map"] = map_path;
  j["scans"] = d.wifi.size();
  j["scans_without_known_ap"] = unknown_scans;
  j["steps_from"] = d.odometry.empty() ? "random walk" : "pedestrian dead reckoning";
  j["heading_from"] = compass ? "compass" : "integrated turn rate";
  j["likelihood"] = ToString(options->particle_filter.likelihood);
  j["particles"] = options->particle_filter.particles;
  j["resamplings"] = filter.resamplings();
  if (map->truth_from_map()) {
    j["errors_after_map_alignment"] = true;  // the map is a run's: scored in the truth's frame
    j["map_to_truth_rmse_m"] = map->truth_from_map()->rmse_m;
  }
  if (!filter_errors.empty()) {
    nlohmann::ordered_json f = ErrorSummary(filter_errors);
    for (auto& [key, value] : f.items()) j[key] = value;
    j["knn_baseline"] = ErrorSummary(knn_errors);
  }
  const std::string summary = j.dump(2) + "\n";
  StatusOr<std::unique_ptr<DiskFolder>> folder = DiskFolder::Open(args->values.at("--out"));
  if (!folder.ok()) return fail(folder.status());
  Status written = folder.value()->Write({{"config.toml", PrintLocateConfig(*options)},
                                          {"trajectory_tum.txt", tum.str()},
                                          {"errors.csv", errors.str()},
                                          {"candidates.csv", candidates.str()},
                                          {"summary.json", summary}});
  if (!written.ok()) return fail(written);
  if (!args->quiet) std::cout << summary;
  return kExitOk;
}

}  // namespace ratslam
