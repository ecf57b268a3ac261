// Phone localisation (Kudo and Miura, section IV), the costs the issue asks for:
//  - WifiMapBuild: GP fit and grid precomputation for 2,000 poses and 200 APs (poses every 2.4 m
//    along corridors of a 120 x 60 m floor, each scan hearing the APs within 25 m, about 46).
//  - FilterScan: one particle-filter update of 5,000 particles by a 30-AP scan, and one step;
//    against one scan per second, the real-time ratio is 1 s / time. Baseline: the same update
//    with 500 particles (cost should scale with the count).
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>
#include <vector>

#include "common/random.h"
#include "fusion/phone_localisation/particle_filter.h"
#include "fusion/phone_localisation/wifi_gp_map.h"

namespace ratslam {
namespace {

struct Floor {
  std::vector<Point2> aps;
  std::vector<WifiMapSample> samples;
  Floor() {
    Random r(3);
    for (int a = 0; a < 200; ++a) aps.push_back({r.Uniform(0, 120), r.Uniform(0, 60)});
    // Corridors every 15 m both ways, walked at a scan every 2.4 m.
    for (double y = 0; y <= 60 && samples.size() < 2000; y += 15) {
      for (double x = 0; x <= 120 && samples.size() < 2000; x += 2.4)
        samples.push_back(At({x, y}, &r));
    }
    for (double x = 0; x <= 120 && samples.size() < 2000; x += 15) {
      for (double y = 0; y <= 60 && samples.size() < 2000; y += 2.4)
        samples.push_back(At({x, y}, &r));
    }
    while (samples.size() < 2000) samples.push_back(At({r.Uniform(0, 120), 30.0}, &r));
  }
  WifiMapSample At(const Point2& p, Random* r) const {
    WifiMapSample s{p, 0, {}};
    for (size_t a = 0; a < aps.size(); ++a) {
      const double d = std::hypot(p.x - aps[a].x, p.y - aps[a].y);
      if (d < 25)
        s.readings.emplace_back("ap" + std::to_string(a),
                                -35 - 25 * std::log10(1 + d) + r->Gaussian(0, 3));
    }
    return s;
  }
};

const Floor& TheFloor() {
  static const Floor floor;
  return floor;
}

void BM_WifiMapBuild(benchmark::State& state) {
  const Floor& f = TheFloor();
  size_t readings = 0;
  for (const auto& s : f.samples) readings += s.readings.size();
  for (auto _ : state) {
    StatusOr<WifiGpMap> map = WifiGpMap::Build(f.samples, WifiGpOptions());
    benchmark::DoNotOptimize(map);
    state.counters["cells"] = static_cast<double>(map->stored_cells());
  }
  state.counters["poses"] = static_cast<double>(f.samples.size());
  state.counters["readings_per_scan"] = static_cast<double>(readings) / f.samples.size();
}
BENCHMARK(BM_WifiMapBuild)->Unit(benchmark::kSecond)->Iterations(1);

void BM_FilterScan(benchmark::State& state) {
  const Floor& f = TheFloor();
  static const WifiGpMap map = *WifiGpMap::Build(f.samples, WifiGpOptions());
  ParticleFilterOptions options;
  options.particles = static_cast<int>(state.range(0));
  ParticleFilter filter(map, options);
  (void)filter.Initialise(true);
  Random r(5);
  std::vector<std::vector<std::pair<std::string, double>>> scans;
  for (int i = 0; i < 16; ++i) {
    auto s = f.At({r.Uniform(0, 120), 30.0}, &r).readings;
    if (s.size() > 30) s.resize(30);
    scans.push_back(s);
  }
  size_t i = 0;
  for (auto _ : state) {
    filter.Step(0.7, 0.1);
    benchmark::DoNotOptimize(filter.Update(scans[i++ % scans.size()]));
  }
}
BENCHMARK(BM_FilterScan)->Arg(5000)->Arg(500)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace ratslam

BENCHMARK_MAIN();
