// Classic camera template matching: one query against N stored 60x10 templates, shifts +-5.
// Baseline: the straightforward comparison on floating-point templates.
// BM_SyntheticRouteViews: real views, the built-in synthetic loop (configs/synthetic.toml's
// crop), the first laps stored and the next lap's views as queries, Compare (with the exact
// column-sum bound, with and without a cutoff) against the full scan of every template
// (Differences) in the same run.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "common/random.h"
#include "common/scratch_dir.h"
#include "dataset/image_loader.h"
#include "dataset/synthetic_dataset.h"
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
  sensors::ClassicCameraOptions options;
  options.template_width_px = kWidth;
  options.template_height_px = kHeight;
  options.shift_px = kShift;
  sensors::ClassicCameraMatcher matcher(options);
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

// Arguments: scan (0 Compare with the bound, 1 the full scan, 2 Compare with a cutoff of
// OpenRatSLAM's 0.004, as Observe does when almost every frame is a new template), and the laps
// stored (1, 3 or 9 of a 10-lap loop); the next lap's views are the queries. Flat cost over the
// laps is the aim of the cutoff's index.
void BM_SyntheticRouteViews(benchmark::State& state) {
  constexpr int kLaps = 10;
  static const auto* data = [] {
    auto* d = new std::pair<std::vector<std::vector<uint8_t>>, sensors::ClassicCameraOptions>();
    sensors::ClassicCameraOptions& options = d->second;
    options.crop_top_px = 8;
    options.crop_bottom_px = 32;
    ScratchDir folder("template_benchmark");
    dataset::SyntheticOptions synthetic;
    synthetic.laps = kLaps;
    StatusOr<dataset::Dataset> dataset =
        dataset::WriteSyntheticDataset(synthetic, (folder.path() / "d").string());
    if (!dataset.ok()) return d;
    sensors::ClassicCameraMatcher matcher(options);
    dataset::FileImageLoader loader;
    for (const ImageRow& row : dataset->images) {
      StatusOr<GrayImage> image = loader.Load(dataset->ImagePath(row));
      if (!image.ok()) return d;
      d->first.push_back(
          matcher.MakeTemplate({image->width, image->height, image->width, image->pixels.data()})
              .value());
    }
    return d;
  }();
  if (data->first.empty()) {
    state.SkipWithError("could not make the synthetic views");
    return;
  }
  const std::vector<std::vector<uint8_t>>& views = data->first;
  const int scan = static_cast<int>(state.range(0));
  const size_t per_lap = views.size() / kLaps;
  const size_t stored = per_lap * static_cast<size_t>(state.range(1));
  sensors::ClassicCameraMatcher matcher(data->second);
  for (size_t i = 0; i < stored; ++i) matcher.Add(views[i]);
  size_t next = stored;
  for (auto _ : state) {
    const std::vector<uint8_t>& query = views[next];
    next = next + 1 < stored + per_lap ? next + 1 : stored;
    if (scan == 0) {
      benchmark::DoNotOptimize(matcher.Compare(query));
    } else if (scan == 1) {
      benchmark::DoNotOptimize(matcher.Differences(query));
    } else {
      benchmark::DoNotOptimize(matcher.Compare(query, -1, 0.004));
    }
  }
  state.counters["templates"] = static_cast<double>(stored);
  if (scan != 1) {
    const double queries = static_cast<double>(state.iterations());
    state.counters["full_comparisons_per_query"] =
        static_cast<double>(matcher.full_comparisons()) / queries;
    state.counters["bounds_checked_per_query"] =
        static_cast<double>(matcher.bounds_checked()) / queries;
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(stored));
}
BENCHMARK(BM_SyntheticRouteViews)
    ->ArgNames({"scan", "laps"})
    ->ArgsProduct({{0, 1, 2}, {1, 3, 9}})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace ratslam

BENCHMARK_MAIN();
