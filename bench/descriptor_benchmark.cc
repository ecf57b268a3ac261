// The descriptor front end's query (fusion/descriptor_front_end.cc): cosine similarity of one
// descriptor against every stored one, as the issue sizes it (50k stored descriptors of 512
// floats), through the front end itself. Baseline in the same run: the same dot products as a
// plain scalar loop over the same matrix.
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>

#include "common/byte_buffer.h"
#include "common/random.h"
#include "fusion/front_end.h"

namespace ratslam {
namespace {

constexpr size_t kDimensions = 512;

std::vector<float> UnitRows(size_t rows, uint64_t seed) {
  Random random(seed);
  std::vector<float> v(rows * kDimensions);
  for (size_t r = 0; r < rows; ++r) {
    double norm2 = 0.0;
    for (size_t k = 0; k < kDimensions; ++k) {
      const double x = random.Gaussian();
      v[r * kDimensions + k] = static_cast<float>(x);
      norm2 += x * x;
    }
    const double inverse = 1.0 / std::sqrt(norm2);
    for (size_t k = 0; k < kDimensions; ++k) v[r * kDimensions + k] *= static_cast<float>(inverse);
  }
  return v;
}

struct World {
  std::vector<float> stored;  // unit rows
  dataset::Dataset dataset;   // query images at times 0, 1, ...
  std::unique_ptr<fusion::FrontEnd> front_end;
};

// `stored` templates already in the front end (through its state, as a loaded map would have
// them); 64 query images, each a stored descriptor plus noise, so every query matches and the
// store does not grow.
std::unique_ptr<World> MakeWorld(size_t stored) {
  auto w = std::make_unique<World>();
  w->stored = UnitRows(stored, 1);
  constexpr size_t kQueries = 64;
  const std::vector<float> noise = UnitRows(kQueries, 2);
  dataset::DescriptorMatrix queries{kQueries, kDimensions, {}};
  for (size_t q = 0; q < kQueries; ++q) {
    const size_t target = (q * 7919) % stored;
    for (size_t k = 0; k < kDimensions; ++k) {
      queries.values.push_back(w->stored[target * kDimensions + k] +
                               0.1f * noise[q * kDimensions + k]);
    }
    ImageRow image;
    image.time_s = 1000.0 + static_cast<double>(q);
    w->dataset.images.push_back(image);
  }
  fusion::FrontEndSettings settings;
  settings.front_end.kind = fusion::FrontEndKind::kDescriptors;
  fusion::FrontEndResources resources;
  resources.descriptors = fusion::DescriptorTable::Make(queries, w->dataset, "queries").value();
  w->front_end = fusion::CreateFrontEnd(settings, resources);
  ByteWriter state;
  state.Pod(static_cast<uint64_t>(kDimensions));
  state.PodVector(w->stored);
  state.PodVector(std::vector<double>(stored, 0.0));
  if (!w->front_end->DecodeState(state.bytes()).ok()) return nullptr;
  return w;
}

void BM_DescriptorQuery(benchmark::State& state) {
  const auto w = MakeWorld(static_cast<size_t>(state.range(0)));
  if (!w) {
    state.SkipWithError("state rejected");
    return;
  }
  size_t q = 0;
  const GrayImage none;
  for (auto _ : state) {
    auto d = w->front_end->OnImage(1000.0 + static_cast<double>(q++ % 64), none);
    if (!d.ok() || !d.value() || d.value()->view.is_new) {
      state.SkipWithError("a query did not match");
      return;
    }
    benchmark::DoNotOptimize(d);
  }
  state.counters["templates"] = static_cast<double>(w->front_end->size());
}
BENCHMARK(BM_DescriptorQuery)->Arg(1000)->Arg(10000)->Arg(50000)->Unit(benchmark::kMicrosecond);

// Baseline: the same best-cosine search as a scalar double loop.
void BM_DescriptorQueryScalarBaseline(benchmark::State& state) {
  const size_t n = static_cast<size_t>(state.range(0));
  const std::vector<float> stored = UnitRows(n, 1);
  const std::vector<float> query = UnitRows(1, 2);
  for (auto _ : state) {
    size_t best = 0;
    float best_score = -2.0f;
    for (size_t r = 0; r < n; ++r) {
      float dot = 0.0f;
      const float* row = stored.data() + r * kDimensions;
      for (size_t k = 0; k < kDimensions; ++k) dot += row[k] * query[k];
      if (dot > best_score) {
        best_score = dot;
        best = r;
      }
    }
    benchmark::DoNotOptimize(best);
  }
}
BENCHMARK(BM_DescriptorQueryScalarBaseline)
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(50000)
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace ratslam

BENCHMARK_MAIN();
