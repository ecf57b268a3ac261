// The image-sequence benchmark's cost: a route of N references against N queries (Nordland's
// half is 1,788 x 1,788 frames of 64 x 32), every query placed by a 10-frame sequence and by its
// single frame. Baseline in the same run: the plain scalar difference matrix alone, the part a
// full-matrix SeqSLAM computes before any search.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <vector>

#include "common/random.h"
#include "sensors/sequence_matcher.h"

namespace ratslam {
namespace {

constexpr int kW = 64, kH = 32;

std::vector<sensors::PreparedFrame> Route(int n, uint64_t seed, double noise) {
  Random random(seed);
  std::vector<sensors::PreparedFrame> frames;
  for (int i = 0; i < n; ++i) {
    Random place(1000 + i);
    std::vector<uint8_t> p(kW * kH);
    for (uint8_t& v : p) {
      v = static_cast<uint8_t>(
          std::clamp(place.Uniform(20, 230) + random.Gaussian(0, noise), 0.0, 255.0));
    }
    frames.push_back(sensors::PrepareFrame(p.data(), kW, kH, 8, 8.0));
  }
  return frames;
}

void BM_MatchRoute(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const std::vector<sensors::PreparedFrame> references = Route(n, 1, 0), queries = Route(n, 2, 30);
  sensors::SequenceMatcher matcher{sensors::SequenceMatcherOptions{}};
  for (const sensors::PreparedFrame& f : references) (void)matcher.AddReference(f);
  for (auto _ : state) {
    matcher.ResetQueries();
    int right = 0;
    for (int q = 0; q < n; ++q)
      right += matcher.AddQuery(queries[q]).value().sequence.reference == q;
    benchmark::DoNotOptimize(right);
  }
  state.counters["queries_per_s"] =
      benchmark::Counter(static_cast<double>(n) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_MatchRoute)->Arg(500)->Arg(1788)->Unit(benchmark::kMillisecond);

void BM_ScalarDifferenceMatrix(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const std::vector<sensors::PreparedFrame> references = Route(n, 1, 0), queries = Route(n, 2, 30);
  std::vector<float> matrix(static_cast<size_t>(n) * n);
  for (auto _ : state) {
    for (int q = 0; q < n; ++q) {
      for (int r = 0; r < n; ++r) {
        const std::vector<uint8_t>& a = queries[q].bytes;
        const std::vector<uint8_t>& b = references[r].bytes;
        uint32_t sum = 0;
        for (size_t i = 0; i < a.size(); ++i) sum += std::abs(int(a[i]) - int(b[i]));
        matrix[static_cast<size_t>(q) * n + r] = static_cast<float>(sum) / (kW * kH);
      }
    }
    benchmark::DoNotOptimize(matrix.data());
  }
}
BENCHMARK(BM_ScalarDifferenceMatrix)->Arg(500)->Arg(1788)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace ratslam

BENCHMARK_MAIN();
