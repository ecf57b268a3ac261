// Classic camera template matching: one query against N stored 60x10 templates, shifts +-5.
// Baseline: the straightforward comparison on floating-point templates.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "common/random.h"
#include "sensors/classic_camera_matcher.h"

namespace ratslam {
namespace {

constexpr int kWidth = 60, kHeight = 10, kShift = 5;

std::vector<uint8_t> RandomImage(Random& rng) {
  std::vector<uint8_t> pixels(kWidth * kHeight);
  for (uint8_t& p : pixels) p = static_cast<uint8_t>(rng.NextU64() % 256);
  return pixels;
}

void BM_ClassicTemplateMatching(benchmark::State& state) {
  ClassicCameraOptions options;
  options.template_width_px = kWidth;
  options.template_height_px = kHeight;
  options.shift_px = kShift;
  ClassicCameraMatcher matcher(options);
  Random rng(1);
  const int templates = static_cast<int>(state.range(0));
  for (int i = 0; i < templates; ++i) {
    const std::vector<uint8_t> image = RandomImage(rng);
    matcher.Add(matcher.MakeTemplate({kWidth, kHeight, kWidth, image.data()}).value());
  }
  const std::vector<uint8_t> query_image = RandomImage(rng);
  const std::vector<uint8_t> query =
      matcher.MakeTemplate({kWidth, kHeight, kWidth, query_image.data()}).value();
  for (auto _ : state) benchmark::DoNotOptimize(matcher.Compare(query));
  state.SetItemsProcessed(state.iterations() * templates);  // items/s = templates per second
}
BENCHMARK(BM_ClassicTemplateMatching)
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(50000)
    ->Unit(benchmark::kMillisecond);

void BM_ClassicTemplateMatchingFloatBaseline(benchmark::State& state) {
  Random rng(1);
  const int templates = static_cast<int>(state.range(0));
  std::vector<std::vector<double>> stored(templates, std::vector<double>(kWidth * kHeight));
  for (auto& t : stored)
    for (double& v : t) v = rng.Uniform();
  std::vector<double> query(kWidth * kHeight);
  for (double& v : query) v = rng.Uniform();
  for (auto _ : state) {
    double best = 1e300;
    for (const auto& t : stored) {
      for (int s = -kShift; s <= kShift; ++s) {
        double sum = 0.0;
        int n = 0;
        for (int y = 0; y < kHeight; ++y)
          for (int u = std::max(0, -s); u < std::min(kWidth, kWidth - s); ++u) {
            sum += std::abs(query[y * kWidth + u + s] - t[y * kWidth + u]);
            ++n;
          }
        best = std::min(best, sum / n);
      }
    }
    benchmark::DoNotOptimize(best);
  }
  state.SetItemsProcessed(state.iterations() * templates);
}
BENCHMARK(BM_ClassicTemplateMatchingFloatBaseline)
    ->Arg(1000)
    ->Arg(10000)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace ratslam

BENCHMARK_MAIN();
