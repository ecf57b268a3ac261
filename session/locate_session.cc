#include "session/locate_session.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "common/number_text.h"
#include "dataset/dataset_loader.h"
#include "dataset/ipin_log.h"
#include "session/evaluation_baselines.h"

namespace ratslam::session {

StatusOr<std::vector<dataset::Dataset>> LoadInOneFrame(
    const std::vector<std::string>& paths, dataset::PhoneLogOptions phone,
    std::optional<std::pair<double, double>>* origin) {
  if (*origin) phone.reference = dataset::GeoReference{(*origin)->first, (*origin)->second};
  std::vector<dataset::Dataset> out;
  for (const std::string& path : paths) {
    StatusOr<dataset::DatasetFormat> format = dataset::DetectDatasetFormat(path);
    if (!format.ok()) return format.status();
    if (format.value() == dataset::DatasetFormat::kIpinLog) {
      dataset::PhoneLogReport report;
      StatusOr<dataset::Dataset> d = dataset::ReadIpinLog(path, phone, &report);
      if (!d.ok()) return d.status();
      if (!phone.reference) {
        phone.reference = report.reference;
        *origin = std::make_pair(report.reference.latitude_deg, report.reference.longitude_deg);
      }
      out.push_back(std::move(d.value()));
    } else {
      StatusOr<dataset::Dataset> d = dataset::LoadDataset(path, phone);
      if (!d.ok()) return d.status();
      out.push_back(std::move(d.value()));
    }
  }
  return out;
}

std::vector<std::pair<std::string, double>> ScanReadings(const WifiScan& scan) {
  std::vector<std::pair<std::string, double>> r;
  for (const WifiReading& w : scan.readings) r.emplace_back(w.bssid, w.rssi_dbm);
  return r;
}

nlohmann::ordered_json LocationErrorSummary(std::vector<double> all) {
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

Point2 MapToTruth(const phone::WifiGpMap& map, const Point2& p) {
  return map.truth_from_map() ? Apply(*map.truth_from_map(), p) : p;
}
Point2 TruthToMap(const phone::WifiGpMap& map, const Point2& p) {
  return map.truth_from_map() ? ApplyInverse(*map.truth_from_map(), p) : p;
}

StatusOr<PhoneSetup> SetUpPhone(const phone::LocateOptions& options,
                                const std::string& wifi_map_path, const std::string& data_path,
                                bool lenient) {
  PhoneSetup setup;
  setup.options = options;
  StatusOr<phone::WifiGpMap> map = phone::WifiGpMap::Load(wifi_map_path);
  if (!map.ok()) return map.status();
  setup.map = std::move(map).value();
  dataset::PhoneLogOptions phone;
  phone.lenient = lenient;
  phone.pdr = options.pdr;
  std::optional<std::pair<double, double>> origin = setup.map.geo_reference_deg();
  StatusOr<std::vector<dataset::Dataset>> data = LoadInOneFrame({data_path}, phone, &origin);
  if (!data.ok()) return data.status();
  setup.data = std::move(data.value().front());
  if (setup.data.wifi.empty()) {
    return Status::Error(data_path + ": no Wi-Fi scan to locate the phone by");
  }
  // The filter's time is about particles x scans x 4 us (measured: 1e6 particles over the 77
  // scans of IPIN route 22, repetition 03, took 318 s on this project's 2-core machine, 1e5 took
  // 28 s): a count that would take over half an hour is refused before it starts (10 million
  // particles once ran for most of an hour on a walk of a minute).
  constexpr double kSecondsPerParticleScan = 4.1e-6;
  constexpr double kMostSeconds = 1800.0;
  const double estimate = kSecondsPerParticleScan * options.particle_filter.particles *
                          static_cast<double>(setup.data.wifi.size());
  if (estimate > kMostSeconds) {
    return Status::Error(
        "[particle_filter] particles = " + std::to_string(options.particle_filter.particles) +
        " would take about " + std::to_string(static_cast<long long>(estimate / 60)) +
        " minutes over " + std::to_string(setup.data.wifi.size()) +
        " scans (at most 30 are allowed): use fewer particles");
  }
  return setup;
}

void FilterPhoneLog(const dataset::Dataset& d, const phone::WifiGpMap& map,
                    phone::ParticleFilter* filter, double until_s,
                    const std::function<void(const WifiScan&, size_t)>& on_scan) {
  const bool compass = !d.compass.empty();
  std::optional<double> heading, last_time, last_odometry;
  double integrated_heading = 0.0;
  for (const dataset::Event& e : dataset::MergeEvents(d)) {
    if (e.time_s > until_s) break;
    if (e.type == dataset::EventType::kCompass) {
      heading = d.compass[e.index].heading_rad;
    } else if (e.type == dataset::EventType::kOdometry) {
      const OdometryRow& row = d.odometry[e.index];
      const double dt = last_odometry ? row.time_s - *last_odometry : 0.0;
      last_odometry = row.time_s;
      integrated_heading += row.turn_rate_rad_per_s * dt;
      const double forward = row.forward_speed_m_per_s * dt;
      if (forward != 0.0) {
        filter->Step(forward,
                     compass && heading ? *heading + map.compass_to_map_rad() : integrated_heading);
      }
    } else if (e.type == dataset::EventType::kWifi) {
      const WifiScan& scan = d.wifi[e.index];
      if (d.odometry.empty() && last_time) filter->Diffuse(scan.time_s - *last_time);
      last_time = scan.time_s;
      on_scan(scan, filter->Update(ScanReadings(scan)));
    }
  }
}

namespace {

// The weighted 3-NN fingerprint answer per scan of `d` on the map's own training scans.
std::vector<fabmap::Estimate> KnnOnTrainingScans(const phone::WifiGpMap& map,
                                                 const dataset::Dataset& d) {
  std::vector<fabmap::EvaluationNode> map_nodes;
  for (const phone::WifiMapSample& s : map.training_samples()) {
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
  return KnnEstimates(map_nodes, queries);
}

}  // namespace

StatusOr<LocateResult> Locate(const PhoneSetup& setup, const std::string& data_label,
                              const std::string& map_label) {
  const phone::WifiGpMap& map = setup.map;
  const phone::LocateOptions& options = setup.options;
  const dataset::Dataset& d = setup.data;
  phone::ParticleFilter filter(map, options.particle_filter);
  const bool compass = !d.compass.empty();
  Status initialised = filter.Initialise(compass);
  if (!initialised.ok()) return initialised;

  LocateResult result;
  size_t unknown_scans = 0;
  const std::vector<fabmap::Estimate> knn = KnnOnTrainingScans(map, d);
  size_t scan_index = 0;
  FilterPhoneLog(d, map, &filter, std::numeric_limits<double>::infinity(),
                 [&](const WifiScan& scan, size_t known) {
                   unknown_scans += known == 0;
                   LocatedScan s;
                   s.time_s = scan.time_s;
                   s.estimate = filter.Estimate();
                   s.known_aps = known;
                   s.candidates = filter.Candidates();
                   s.truth = dataset::GroundTruthAt(d, scan.time_s);
                   if (s.truth) {
                     // A map made from a run is in the run's frame and has one floor: its
                     // estimates are scored after its alignment onto the truth, on position alone.
                     const GroundTruthRow& truth = *s.truth;
                     auto floor_differs = [&](int floor) {
                       return !map.truth_from_map() && floor != truth.floor;
                     };
                     const Point2 e = MapToTruth(map, {s.estimate.x_m, s.estimate.y_m});
                     s.error_m = floor_differs(s.estimate.floor)
                                     ? std::numeric_limits<double>::infinity()
                                     : std::hypot(e.x - truth.x_m, e.y - truth.y_m);
                     const fabmap::Estimate& k = knn[scan_index];
                     const Point2 ke = MapToTruth(map, {k.x_m, k.y_m});
                     s.knn_error_m = !k.located || floor_differs(k.floor)
                                         ? std::numeric_limits<double>::infinity()
                                         : std::hypot(ke.x - truth.x_m, ke.y - truth.y_m);
                     result.filter_errors_m.push_back(s.error_m);
                     result.knn_errors_m.push_back(s.knn_error_m);
                   }
                   result.scans.push_back(std::move(s));
                   ++scan_index;
                 });
  nlohmann::ordered_json& j = result.summary;
  j["data"] = data_label;
  j["wifi_map"] = map_label;
  j["scans"] = d.wifi.size();
  j["scans_without_known_ap"] = unknown_scans;
  j["steps_from"] = d.odometry.empty() ? "random walk" : "pedestrian dead reckoning";
  j["heading_from"] = compass ? "compass" : "integrated turn rate";
  j["likelihood"] = ToString(options.particle_filter.likelihood);
  j["particles"] = options.particle_filter.particles;
  j["resamplings"] = filter.resamplings();
  j["walls"] = map.walls().size();
  j["wall_crossings"] = filter.wall_crossings();
  if (options.particle_filter.online_rssi_offset) j["rssi_offset_db"] = filter.rssi_offset_db();
  if (map.truth_from_map()) {
    j["errors_after_map_alignment"] = true;  // the map is a run's: scored in the truth's frame
    j["map_to_truth_rmse_m"] = map.truth_from_map()->rmse_m;
  }
  if (!result.filter_errors_m.empty()) {
    nlohmann::ordered_json f = LocationErrorSummary(result.filter_errors_m);
    for (auto& [key, value] : f.items()) j[key] = value;
    j["knn_baseline"] = LocationErrorSummary(result.knn_errors_m);
  }
  return result;
}

std::string LocateResult::TrajectoryTum() const {
  std::ostringstream tum;
  tum << "# timestamp tx ty tz qx qy qz qw (particle filter estimate at each Wi-Fi scan)\n";
  for (const LocatedScan& s : scans) {
    tum << ShortestNumber(s.time_s) << ' ' << ShortestNumber(s.estimate.x_m) << ' '
        << ShortestNumber(s.estimate.y_m) << " 0 0 0 0 1\n";
  }
  return tum.str();
}

std::string LocateResult::ErrorsCsv() const {
  std::ostringstream errors;
  errors << "time_s,x_m,y_m,floor,known_aps,true_x_m,true_y_m,true_floor,error_m,knn_error_m\n";
  for (const LocatedScan& s : scans) {
    errors << ShortestNumber(s.time_s) << ',' << ShortestNumber(s.estimate.x_m) << ','
           << ShortestNumber(s.estimate.y_m) << ',' << s.estimate.floor << ',' << s.known_aps;
    if (s.truth) {
      errors << ',' << ShortestNumber(s.truth->x_m) << ',' << ShortestNumber(s.truth->y_m) << ','
             << s.truth->floor << ',' << ShortestNumber(s.error_m) << ','
             << ShortestNumber(s.knn_error_m) << '\n';
    } else {
      errors << ",,,,,\n";
    }
  }
  return errors.str();
}

std::string LocateResult::CandidatesCsv() const {
  std::ostringstream candidates;
  candidates << "time_s,rank,x_m,y_m,weight\n";
  for (const LocatedScan& s : scans) {
    for (size_t k = 0; k < s.candidates.size(); ++k) {
      candidates << ShortestNumber(s.time_s) << ',' << k << ','
                 << ShortestNumber(s.candidates[k].first.x) << ','
                 << ShortestNumber(s.candidates[k].first.y) << ','
                 << ShortestNumber(s.candidates[k].second) << '\n';
    }
  }
  return candidates.str();
}

}  // namespace ratslam::session
