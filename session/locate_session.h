// Locating a phone in a Wi-Fi map (Kudo and Miura, section IV) as a library session: the phone
// log read in the map's frame, the particle filter run over it, each scan's estimate scored
// against the ground truth beside the weighted 3-NN fingerprint answer on the map's own training
// scans, and the outputs of `ratslam locate` (trajectory_tum.txt, errors.csv, candidates.csv,
// summary.json) as text. The command line and Python drive it; `call` and `wifi-map` share its
// loading and filtering.
#ifndef RATSLAM_SESSION_LOCATE_SESSION_H_
#define RATSLAM_SESSION_LOCATE_SESSION_H_

#include <cstddef>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/status.h"
#include "dataset/dataset.h"
#include "dataset/phone_log.h"
#include "phone/locate_options.h"
#include "phone/particle_filter.h"
#include "phone/wifi_gp_map.h"

namespace ratslam::session {

// Loads data sets in one frame: IPIN logs share the first one's geographic origin (or the given
// one, `*origin`). Sets `*origin` to the origin used, if any log had one.
StatusOr<std::vector<dataset::Dataset>> LoadInOneFrame(
    const std::vector<std::string>& paths, dataset::PhoneLogOptions phone,
    std::optional<std::pair<double, double>>* origin);

// A scan's readings as the Wi-Fi map takes them.
std::vector<std::pair<std::string, double>> ScanReadings(const WifiScan& scan);

// Location errors in metres, an infinite one for a wrong floor: `count` (on the right floor),
// `wrong_floor`, and when any: `mean_error_m`, `median_error_m`, `p75_error_m`, `p90_error_m`.
nlohmann::ordered_json LocationErrorSummary(std::vector<double> errors_m);

// A point of the Wi-Fi map's frame in the ground truth's frame (the same unless the map is a
// run's), and back.
Point2 MapToTruth(const phone::WifiGpMap& map, const Point2& p);
Point2 TruthToMap(const phone::WifiGpMap& map, const Point2& p);

// What locate and call share: options, the Wi-Fi map and the phone log read in its frame.
struct PhoneSetup {
  phone::LocateOptions options;
  phone::WifiGpMap map;
  dataset::Dataset data;
};
// Loads the map and the log (which must hold a Wi-Fi scan), and refuses a particle count that
// would take over half an hour on it.
StatusOr<PhoneSetup> SetUpPhone(const phone::LocateOptions& options,
                                const std::string& wifi_map_path, const std::string& data_path,
                                bool lenient);

// Replays a phone log through the filter in time order up to `until_s`: PDR steps (heading from
// the compass, turned into the map's frame, or integrated turn rate), a random walk between
// scans without odometry, and a weight update per scan, after which `on_scan` runs with the
// number of readings the map knew.
void FilterPhoneLog(const dataset::Dataset& d, const phone::WifiGpMap& map,
                    phone::ParticleFilter* filter, double until_s,
                    const std::function<void(const WifiScan&, size_t)>& on_scan);

// One scan of the located log.
struct LocatedScan {
  double time_s = 0.0;
  phone::LocationEstimate estimate;
  size_t known_aps = 0;                               // readings the map knew
  std::vector<std::pair<Point2, double>> candidates;  // the filter's, best first, with weights
  std::optional<GroundTruthRow> truth;
  double error_m = 0.0;      // with truth: in the truth's frame, infinite on the wrong floor
  double knn_error_m = 0.0;  // the same for the weighted 3-NN fingerprint answer
};

struct LocateResult {
  std::vector<LocatedScan> scans;
  std::vector<double> filter_errors_m, knn_errors_m;  // at the scans with truth
  // summary.json without `run`; `data` and `wifi_map` are the labels given.
  nlohmann::ordered_json summary;
  std::string TrajectoryTum() const;
  std::string ErrorsCsv() const;
  std::string CandidatesCsv() const;
};

// Runs the filter over the setup's log. Fails only when the filter cannot start.
StatusOr<LocateResult> Locate(const PhoneSetup& setup, const std::string& data_label,
                              const std::string& map_label);

}  // namespace ratslam::session

#endif  // RATSLAM_SESSION_LOCATE_SESSION_H_
