// Building a Gaussian-process Wi-Fi map (Kudo and Miura, section III) as a library session: the
// scans of data sets with ground truth placed where the truth says, or the scans of a replay
// placed where the run's final map puts the robot (the run's frame, with the compass's offset
// to it and the map's alignment onto the truth). `ratslam wifi-map` and Python drive it.
#ifndef RATSLAM_SESSION_WIFI_MAP_SESSION_H_
#define RATSLAM_SESSION_WIFI_MAP_SESSION_H_

#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "common/status.h"
#include "phone/locate_options.h"
#include "phone/wifi_gp_map.h"

namespace ratslam::session {

struct WifiMapInput {
  std::vector<std::string> data;   // data sets (IPIN logs in the first one's frame)
  std::optional<std::string> run;  // a replay's run folder of `data`: positions from its map
  bool lenient = false;            // skip bad lines of phone logs
};

struct BuiltWifiMap {
  phone::WifiGpMap map;
  size_t scans = 0;    // Wi-Fi scans read
  size_t samples = 0;  // of which placed on the map
  // The summary of `ratslam wifi-map` without `seconds` and `run`; `wifi_map` is the label given.
  nlohmann::ordered_json summary;
};

// Fails when no scan could be placed (no ground truth at any scan's time, or none within the
// run's trajectory), or when the run replayed other data.
StatusOr<BuiltWifiMap> BuildWifiMap(const phone::LocateOptions& options, const WifiMapInput& input,
                                    const std::string& map_label);

}  // namespace ratslam::session

#endif  // RATSLAM_SESSION_WIFI_MAP_SESSION_H_
