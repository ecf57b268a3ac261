// What `ratslam wifi-map` and `ratslam locate` are configured by; one TOML section per member
// (io/config.h reads and prints it like the replay's configuration).
#ifndef RATSLAM_PHONE_LOCATE_OPTIONS_H_
#define RATSLAM_PHONE_LOCATE_OPTIONS_H_

#include <string>

#include "phone/gaussian_process.h"
#include "phone/particle_filter.h"
#include "sensors/pedestrian_dead_reckoning.h"

namespace ratslam::phone {

struct LocateOptions {
  WifiGpOptions wifi_map;                 // the GP maps (wifi-map)
  ParticleFilterOptions particle_filter;  // the filter (locate)
  sensors::PdrOptions pdr;                // steps from the phone's IMU (IPIN logs)

  bool IsValid(std::string* error) const {
    std::string inner;
    auto check = [&](bool ok, const char* section) {
      if (!ok && error) *error = std::string(section) + "." + inner;
      return ok;
    };
    return check(wifi_map.IsValid(&inner), "wifi_map") &&
           check(particle_filter.IsValid(&inner), "particle_filter") &&
           check(pdr.IsValid(&inner), "pdr");
  }

  template <typename Visitor>
  void VisitSections(Visitor&& v) {
    v("wifi_map", wifi_map);
    v("particle_filter", particle_filter);
    v("pdr", pdr);
  }
};

}  // namespace ratslam::phone

#endif  // RATSLAM_PHONE_LOCATE_OPTIONS_H_
