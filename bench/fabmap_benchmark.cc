// FABMAP query time against map size and vocabulary size (about 200 words per observation), for
// new places and revisits, and Chow-Liu learning time. The dense FABMAP 1.0 sum is the baseline,
// measured in the same run.
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <utility>

#include "common/random.h"
#include "fusion/fabmap/fabmap.h"
#include "fusion/fabmap/synthetic_words.h"

namespace ratslam::fabmap {
namespace {

SyntheticWordWorld World(uint32_t vocabulary) {
  SyntheticWordWorld w;
  w.vocabulary_size = vocabulary;
  w.mean_words_per_observation = 200;
  return w;
}

std::vector<Observation> Observations(const SyntheticWordWorld& w, int n, uint64_t seed) {
  Random random(seed);
  std::vector<Observation> out;
  for (int i = 0; i < n; ++i) out.push_back(w.Observe(w.SamplePlace(&random), &random));
  return out;
}

// One model per (places, words), built once.
FabmapModel& Model(uint32_t places, uint32_t vocabulary) {
  static std::map<std::pair<uint32_t, uint32_t>, std::unique_ptr<FabmapModel>> cache;
  auto& slot = cache[{places, vocabulary}];
  if (!slot) {
    const SyntheticWordWorld w = World(vocabulary);
    const auto training = Observations(w, 500, 1);
    DetectorBlock block;
    block.count = vocabulary;
    slot = std::make_unique<FabmapModel>(
        *FabmapModel::Create(*LearnChowLiuTree(training, vocabulary), {block}, training, {}));
    Random random(2);
    for (uint32_t i = 0; i < places; ++i) {
      (void)slot->AddPlace(w.Observe(w.SamplePlace(&random), &random));
    }
  }
  return *slot;
}

// Localise over `queries` in turn; counter: the share of places ruled out before their last words.
void TimeQueries(benchmark::State& state, const FabmapModel& model,
                 const std::vector<Observation>& queries) {
  size_t i = 0;
  double ruled_out = 0.0;
  for (auto _ : state) {
    const LocalisationResult r = model.Localise(queries[i++ % queries.size()]);
    ruled_out += r.places_ruled_out;
    benchmark::DoNotOptimize(r);
  }
  state.counters["ruled_out"] =
      ruled_out / static_cast<double>(state.iterations()) / model.places();
}

void BM_FabmapQuery(benchmark::State& state) {
  const uint32_t places = static_cast<uint32_t>(state.range(0));
  const uint32_t vocabulary = static_cast<uint32_t>(state.range(1));
  FabmapModel& model = Model(places, vocabulary);
  const auto queries = Observations(World(vocabulary), 64, 3);
  TimeQueries(state, model, queries);
  state.counters["places"] = places;
  state.counters["words"] = vocabulary;
}
BENCHMARK(BM_FabmapQuery)
    ->ArgsProduct({{1000, 10000, 100000}, {1000, 10000}})
    ->Unit(benchmark::kMicrosecond);

// A mapped place seen again (a second observation of it): one place stands out, so Localise
// rules the others out early.
void BM_FabmapRevisit(benchmark::State& state) {
  const uint32_t places = static_cast<uint32_t>(state.range(0));
  const uint32_t vocabulary = static_cast<uint32_t>(state.range(1));
  FabmapModel& model = Model(places, vocabulary);
  const SyntheticWordWorld w = World(vocabulary);
  // The places Model drew, drawn again with its seed, each observed afresh.
  std::vector<Observation> queries;
  Random random(2), fresh(5);
  for (uint32_t i = 0; i < places && queries.size() < 64; ++i) {
    const Observation place = w.SamplePlace(&random);
    (void)w.Observe(place, &random);
    if (i % (places / 64) == 0) queries.push_back(w.Observe(place, &fresh));
  }
  TimeQueries(state, model, queries);
}
BENCHMARK(BM_FabmapRevisit)
    ->ArgsProduct({{1000, 10000, 100000}, {10000}})
    ->Unit(benchmark::kMicrosecond);

// Baseline: the dense FABMAP 1.0 sum over every word for every place (1k places only).
void BM_DenseFabmap1Query(benchmark::State& state) {
  const uint32_t vocabulary = static_cast<uint32_t>(state.range(0));
  FabmapModel& model = Model(1000, vocabulary);
  const auto queries = Observations(World(vocabulary), 4, 3);
  size_t i = 0;
  for (auto _ : state) {
    const Observation& z = queries[i++ % queries.size()];
    double sum = 0.0;
    for (uint32_t p = 0; p < model.places(); ++p) sum += model.DenseLogLikelihood(z, p);
    benchmark::DoNotOptimize(sum);
  }
}
BENCHMARK(BM_DenseFabmap1Query)->Arg(1000)->Arg(10000)->Unit(benchmark::kMillisecond);

void BM_ChowLiuLearning(benchmark::State& state) {
  const uint32_t vocabulary = static_cast<uint32_t>(state.range(0));
  const auto training = Observations(World(vocabulary), 500, 4);
  for (auto _ : state) benchmark::DoNotOptimize(LearnChowLiuTree(training, vocabulary));
}
BENCHMARK(BM_ChowLiuLearning)->Arg(4000)->Arg(10000)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace ratslam::fabmap

BENCHMARK_MAIN();
