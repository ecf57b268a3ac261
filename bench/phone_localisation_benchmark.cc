// Phone localisation (Kudo and Miura, section IV), the costs the issue asks for:
//  - WifiMapBuild: GP fit and grid precomputation for 2,000 poses and 200 APs (poses every 2.4 m
//    along corridors of a 120 x 60 m floor, each scan hearing the APs within 25 m, about 46).
//  - FilterScan: one particle-filter update of 5,000 particles by a 30-AP scan, and one step;
//    against one scan per second, the real-time ratio is 1 s / time. Baseline: the same update
//    with 500 particles (cost should scale with the count). Arg 2: 0 = no walls, 1 = the floor's
//    corridor walls (a wall along both sides of every corridor, with doors every 7.5 m), so the
//    wall test's share of a step shows.
//  - PlanCall: the robot's route to 12 candidates over an experience graph of 1,869 nodes along
//    the corridors, exact by Held-Karp; baseline: 6 candidates.
#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "common/random.h"
#include "phone/particle_filter.h"
#include "phone/robot_call.h"
#include "phone/wifi_gp_map.h"

namespace ratslam {
namespace {

struct Floor {
  std::vector<Point2> aps;
  std::vector<phone::WifiMapSample> samples;
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
  phone::WifiMapSample At(const Point2& p, Random* r) const {
    phone::WifiMapSample s{p, 0, {}};
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
    StatusOr<phone::WifiGpMap> map = phone::WifiGpMap::Build(f.samples, phone::WifiGpOptions());
    benchmark::DoNotOptimize(map);
    state.counters["cells"] = static_cast<double>(map->stored_cells());
  }
  state.counters["poses"] = static_cast<double>(f.samples.size());
  state.counters["readings_per_scan"] = static_cast<double>(readings) / f.samples.size();
}
BENCHMARK(BM_WifiMapBuild)->Unit(benchmark::kSecond)->Iterations(1);

std::vector<phone::WallSegment> CorridorWalls() {
  std::vector<phone::WallSegment> walls;
  for (double y = 0; y <= 60; y += 15) {
    for (double x = 0; x < 120; x += 7.5) {
      walls.push_back({0, {x + 1.0, y - 1.2}, {x + 7.5, y - 1.2}});
      walls.push_back({0, {x + 1.0, y + 1.2}, {x + 7.5, y + 1.2}});
    }
  }
  return walls;
}

void BM_FilterScan(benchmark::State& state) {
  const Floor& f = TheFloor();
  static const phone::WifiGpMap plain = *phone::WifiGpMap::Build(f.samples, phone::WifiGpOptions());
  static const phone::WifiGpMap walled = [] {
    phone::WifiGpMap m = plain;
    m.set_walls(CorridorWalls());
    return m;
  }();
  const phone::WifiGpMap& map = state.range(1) ? walled : plain;
  phone::ParticleFilterOptions options;
  options.particles = static_cast<int>(state.range(0));
  phone::ParticleFilter filter(map, options);
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
BENCHMARK(BM_FilterScan)
    ->Args({5000, 0})
    ->Args({500, 0})
    ->Args({5000, 1})
    ->Unit(benchmark::kMillisecond);

void BM_PlanCall(benchmark::State& state) {
  // Experiences every 0.6 m along the floor's corridors (every 15 m both ways over 120 x 60 m),
  // each linked to its neighbours along the corridor: 1,869 nodes, about one link per node,
  // like an experience map.
  phone::RouteGraph graph;
  std::map<std::pair<int, int>, uint32_t> id;
  for (int ix = 0; ix <= 200; ++ix) {
    for (int iy = 0; iy <= 100; ++iy) {
      if (ix % 25 && iy % 25) continue;
      id[{ix, iy}] = static_cast<uint32_t>(graph.nodes.size());
      graph.nodes.push_back({0.6 * ix, 0.6 * iy});
    }
  }
  for (const auto& [at, k] : id) {
    for (const auto& next :
         {std::pair{at.first + 1, at.second}, std::pair{at.first, at.second + 1}}) {
      if (auto it = id.find(next); it != id.end()) graph.edges.push_back({k, it->second});
    }
  }
  Random r(8);
  std::vector<Point2> candidates;
  for (int c = 0; c < state.range(0); ++c)
    candidates.push_back({r.Uniform(0, 120), r.Uniform(0, 60)});
  for (auto _ : state) {
    StatusOr<phone::CallPlan> plan = phone::PlanCall(graph, 0, candidates);
    benchmark::DoNotOptimize(plan);
    state.counters["route_m"] = plan->length_m;
  }
  state.counters["nodes"] = static_cast<double>(graph.nodes.size());
  state.counters["edges"] = static_cast<double>(graph.edges.size());
}
BENCHMARK(BM_PlanCall)->Arg(12)->Arg(6)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace ratslam

BENCHMARK_MAIN();
