// Experience-map relaxation.
//  - BM_FullRelaxation: one call of the full scheme (10 passes over every link) on a map of N
//    experiences: a chain with a loop closure every 50 experiences, as a long route with revisits
//    gives.
//  - BM_LongRun: a run of N frames, each adding an experience and relaxing, on a route that goes
//    round a 400-experience loop and links back to the previous lap every 50 frames; time per frame
//    in the first and second half of the run, for the full scheme (the baseline) and the
//    incremental one, and for least squares at loop closures. Flat cost per frame means a ratio
//    near 1. Every lap closing onto the last with 0.2 rad of drift is the incremental scheme's
//    worst case: its region never settles.
#include <benchmark/benchmark.h>

#include <chrono>

#include "ratslam/experience_map.h"

namespace ratslam {
namespace {

void BM_FullRelaxation(benchmark::State& state) {
  ExperienceMapOptions options;
  options.relaxation_scheme = RelaxationScheme::kFull;
  ExperienceMap map(options);
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
BENCHMARK(BM_FullRelaxation)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMicrosecond);

// Arguments: scheme (0 full, 1 incremental, 2 least squares), frames.
void BM_LongRun(benchmark::State& state) {
  constexpr int kLap = 400;
  ExperienceMapOptions options;
  options.relaxation_scheme = state.range(0) == 0   ? RelaxationScheme::kFull
                              : state.range(0) == 1 ? RelaxationScheme::kIncremental
                                                    : RelaxationScheme::kLeastSquares;
  const int n = static_cast<int>(state.range(1));
  using Clock = std::chrono::steady_clock;
  double first_s = 0.0, second_s = 0.0;
  uint64_t updates = 0;
  for (auto _ : state) {
    ExperienceMap map(options);
    const Clock::time_point start = Clock::now();
    Clock::time_point half = start;
    for (int i = 0; i < n; ++i) {
      if (i == n / 2) half = Clock::now();
      // A 2 pi turn per lap plus a small bias: each lap drifts against the last.
      map.Integrate(1.0, 2.0 * 3.14159265358979 / kLap + 0.0005);
      map.CreateExperience(i, {}, i);
      map.Relax();
      if (i >= kLap && i % 50 == 0) {
        (void)map.LinkTo(static_cast<uint32_t>(i - kLap), i);
        map.Relax();
      }
    }
    const Clock::time_point end = Clock::now();
    first_s = std::chrono::duration<double>(half - start).count();
    second_s = std::chrono::duration<double>(end - half).count();
    updates = map.relaxation_link_updates();
    state.SetIterationTime(first_s + second_s);
  }
  const double half_frames = n / 2.0;
  state.counters["first_half_us_per_frame"] = 1e6 * first_s / half_frames;
  state.counters["second_half_us_per_frame"] = 1e6 * second_s / (n - half_frames);
  state.counters["second_over_first"] = second_s / first_s;
  state.counters["link_updates_per_frame"] = static_cast<double>(updates) / n;
}
BENCHMARK(BM_LongRun)
    ->ArgNames({"scheme", "frames"})
    ->Args({0, 1000})
    ->Args({0, 2000})
    ->Args({0, 4000})
    ->Args({1, 1000})
    ->Args({1, 2000})
    ->Args({1, 4000})
    ->Args({2, 1000})
    ->Args({2, 2000})
    ->Args({2, 4000})
    ->UseManualTime()
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace ratslam

BENCHMARK_MAIN();
