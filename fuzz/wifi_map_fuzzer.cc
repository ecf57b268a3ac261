// Wi-Fi map files (`ratslam wifi-map`): errors name the file; a map that decodes answers every
// lookup (inside and outside its grids, on any floor) and carries a particle filter (walls,
// floor changes and sensor resetting included) through a few steps and scans without touching
// memory it does not own.
#include <cmath>
#include <string>

#include "fuzz/fuzz_support.h"
#include "phone/particle_filter.h"
#include "phone/wifi_gp_map.h"

namespace ratslam::fuzz {

std::vector<std::string> FuzzSeeds() {
  std::vector<std::string> seeds;
  for (int floors : {1, 2}) {
    std::vector<phone::WifiMapSample> samples;
    for (int f = 0; f < floors; ++f) {
      for (double x = 0; x <= 12; x += 2) {
        for (double y = 0; y <= 6; y += 3) {
          phone::WifiMapSample s{{x, y}, f, {}};
          for (int a = 0; a < 3; ++a) {
            const double d = std::hypot(x - 6 * a, y - 3);
            if (d < 9)
              s.readings.emplace_back("ap" + std::to_string(a), -40 - 20 * std::log10(1 + d));
          }
          samples.push_back(s);
        }
      }
    }
    phone::WifiGpOptions options;
    options.grid_margin_m = 3.0;
    StatusOr<phone::WifiGpMap> map = phone::WifiGpMap::Build(samples, options);
    if (!map.ok()) InvariantFailed("the seed map failed: " + map.status().message());
    if (floors == 2) {
      map->set_geo_reference_deg(std::make_pair(40.3, -3.7));
      // The frame of a run-made map, and walls (format 2).
      map->set_compass_to_map_rad(0.7);
      RigidAlignment2D a;
      a.rotation_rad = 0.3;
      a.translation_x_m = -2.0;
      map->set_truth_from_map(a);
      map->set_walls({{0, {5, -1}, {5, 4}}, {1, {0, 3}, {12, 3}}});
    }
    seeds.push_back(map->Encode());
  }
  return seeds;
}

}  // namespace ratslam::fuzz

namespace {

int DecodeAndUse(const std::string& bytes) {
  using namespace ratslam;
  StatusOr<phone::WifiGpMap> map = phone::WifiGpMap::Decode(bytes, "w.wifimap");
  if (!map.ok()) {
    if (map.status().message().rfind("w.wifimap", 0) != 0) {
      fuzz::InvariantFailed("error does not name the file: " + map.status().message());
    }
    return 0;
  }
  for (size_t ap = 0; ap < map->bssids().size() + 1; ++ap) {
    for (int floor : {-1, 0, 1, 7}) {
      for (const Point2& p : {Point2{0, 0}, Point2{5.5, 2.5}, Point2{-1e6, 1e6}}) {
        const phone::WifiGpMap::Cell c = map->Predict(ap, floor, p);
        if (std::isnan(c.mean_dbm)) fuzz::InvariantFailed("a lookup returned NaN");
      }
    }
  }
  if (map->stored_cells() > 200000) return 0;  // a filter over a huge map is not the point here
  phone::ParticleFilterOptions options;
  options.particles = 50;
  phone::ParticleFilter filter(*map, options);
  if (!filter.Initialise(true).ok()) return 0;
  std::vector<std::pair<std::string, double>> scan;
  for (const std::string& b : map->bssids()) scan.emplace_back(b, -60.0);
  scan.emplace_back("unknown", -50.0);
  for (int i = 0; i < 3; ++i) {
    filter.Step(1.0, 0.3 * i);
    filter.Diffuse(2.0);
    filter.Update(scan);
  }
  const phone::LocationEstimate e = filter.Estimate();
  if (!std::isfinite(e.x_m) || !std::isfinite(e.y_m)) fuzz::InvariantFailed("estimate not finite");
  (void)filter.Candidates();
  return 0;
}

}  // namespace

// The input as it is (formats 1 and 2 have no checksum), and behind a matching checksum, so that
// mutations reach the decoder (a flipped byte under the checksum is refused:
// particle_filter_test).
extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return ratslam::fuzz::AsIsAndChecksummed(data, size, DecodeAndUse);
}
