// One relaxation call (10 sweeps) on a map of N experiences: a chain with a loop closure every
// 50 experiences, as a long route with revisits gives.
#include <benchmark/benchmark.h>

#include "ratslam/experience_map.h"

namespace ratslam {
namespace {

void BM_Relaxation(benchmark::State& state) {
  ExperienceMap map({});
  const int n = static_cast<int>(state.range(0));
  for (int i = 0; i < n; ++i) {
    map.Integrate(1.0, 0.05);
    map.CreateExperience(i, {}, i);
    if (i >= 100 && i % 50 == 0) {
      (void)map.LinkTo(static_cast<uint32_t>(i - 100), i);
      map.Integrate(1.0, 0.05);
      map.CreateExperience(i, {}, i);
    }
  }
  for (auto _ : state) map.Relax();
  state.counters["links"] = static_cast<double>(map.num_links());
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(map.num_links()) * 10);
}
BENCHMARK(BM_Relaxation)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace ratslam

BENCHMARK_MAIN();
