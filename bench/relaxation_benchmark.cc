// Experience-map relaxation.
//  - BM_FullRelaxation: one call of the full scheme (10 passes over every link) on a map of N
//    experiences: a chain with a loop closure every 50 experiences, as a long route with revisits
//    gives.
//  - BM_LongRun: a run of N frames, each adding an experience and relaxing, on a route that goes
//    round a 400-experience loop and links back to the previous lap every 50 frames; time per frame
//    in the first and second half of the run, for the full scheme (the baseline) and the
//    incremental one (with and without its region cap), and for least squares at loop closures,
//    with time per frame at sizes from 1k to 50k experiences. Flat cost per frame means a ratio
//    near 1. Every lap closing onto the last with 0.2 rad of drift is the incremental scheme's
//    worst case: its region never settles.
#include <benchmark/benchmark.h>

#include <chrono>
#include <string>
#include <utility>
#include <vector>

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

// Arguments: scheme (0 full, 1 incremental without a region cap, 2 incremental with the default
// cap, 3 least squares), frames. Counters: time per frame in the first and second half and their
// ratio, and the time per frame over the 500 frames up to each of 1k, 2k, 5k, 10k, 20k and 50k
// experiences that the run reaches.
void BM_LongRun(benchmark::State& state) {
  constexpr int kLap = 400;
  ExperienceMapOptions options;
  const int64_t scheme = state.range(0);
  options.relaxation_scheme = scheme == 0   ? RelaxationScheme::kFull
                              : scheme == 3 ? RelaxationScheme::kLeastSquares
                                            : RelaxationScheme::kIncremental;
  if (scheme == 1) options.relaxation_max_region_links = 0;
  const int n = static_cast<int>(state.range(1));
  constexpr int kSizes[] = {1000, 2000, 5000, 10000, 20000, 50000};
  constexpr int kWindow = 500;
  using Clock = std::chrono::steady_clock;
  double first_s = 0.0, second_s = 0.0;
  uint64_t updates = 0, capped = 0;
  std::vector<std::pair<int, double>> at_size;  // (size, us per frame over the window before it)
  for (auto _ : state) {
    ExperienceMap map(options);
    at_size.clear();
    const Clock::time_point start = Clock::now();
    Clock::time_point half = start, window = start;
    for (int i = 0; i < n; ++i) {
      if (i == n / 2) half = Clock::now();
      for (int size : kSizes) {
        if (i == size - kWindow) window = Clock::now();
      }
      // A 2 pi turn per lap plus a small bias: each lap drifts against the last.
      map.Integrate(1.0, 2.0 * 3.14159265358979 / kLap + 0.0005);
      map.CreateExperience(i, {}, i);
      map.Relax();
      if (i >= kLap && i % 50 == 0) {
        (void)map.LinkTo(static_cast<uint32_t>(i - kLap), i);
        map.Relax();
      }
      for (int size : kSizes) {
        if (i + 1 == size) {
          at_size.emplace_back(
              size, 1e6 * std::chrono::duration<double>(Clock::now() - window).count() / kWindow);
        }
      }
    }
    const Clock::time_point end = Clock::now();
    first_s = std::chrono::duration<double>(half - start).count();
    second_s = std::chrono::duration<double>(end - half).count();
    updates = map.relaxation_link_updates();
    capped = map.relaxation_capped_passes();
    state.SetIterationTime(first_s + second_s);
  }
  const double half_frames = n / 2.0;
  state.counters["first_half_us_per_frame"] = 1e6 * first_s / half_frames;
  state.counters["second_half_us_per_frame"] = 1e6 * second_s / (n - half_frames);
  state.counters["second_over_first"] = second_s / first_s;
  state.counters["link_updates_per_frame"] = static_cast<double>(updates) / n;
  state.counters["capped_passes"] = static_cast<double>(capped);
  for (const auto& [size, us] : at_size) {
    state.counters["us_per_frame_at_" + std::to_string(size / 1000) + "k"] = us;
  }
}
// Full relaxation and the uncapped region grow with the map: their runs stop at 8k frames.
BENCHMARK(BM_LongRun)
    ->ArgNames({"scheme", "frames"})
    ->Args({0, 2000})
    ->Args({0, 4000})
    ->Args({0, 8000})
    ->Args({1, 2000})
    ->Args({1, 4000})
    ->Args({1, 8000})
    ->Args({2, 2000})
    ->Args({2, 4000})
    ->Args({2, 8000})
    ->Args({2, 20000})
    ->Args({2, 50000})
    ->Args({3, 2000})
    ->Args({3, 4000})
    ->UseManualTime()
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace ratslam

BENCHMARK_MAIN();
