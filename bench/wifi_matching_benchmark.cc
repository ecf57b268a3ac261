// Wi-Fi fingerprint matching: one query against 10k stored fingerprints of about 30 APs each.
// Two AP universes: 230 APs (one building, like the IPIN logs: most fingerprints share APs with
// the query) and 20,000 APs (a campus: few share any). Baseline: the pairwise formula against
// every stored fingerprint, without the BSSID index.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "common/random.h"
#include "sensors/wifi_fingerprint_matcher.h"

namespace ratslam {
namespace {

struct Setup {
  sensors::WifiFingerprintMatcher matcher{sensors::WifiMatcherOptions()};
  std::vector<sensors::Fingerprint> stored;
  sensors::Fingerprint query;
};

Setup Make(int fingerprints, int universe) {
  Setup s;
  Random rng(5);
  auto scan = [&]() {
    // A place: 30 APs clustered around a random point of the universe (nearby APs are heard).
    const int center = static_cast<int>(rng.Uniform() * universe);
    std::vector<std::pair<std::string, double>> r;
    for (int i = 0; i < 30; ++i) {
      const int ap = (center + static_cast<int>(rng.Gaussian(0, 25))) % universe;
      r.push_back({"ap" + std::to_string((ap + universe) % universe), rng.Uniform(-92, -35)});
    }
    return s.matcher.MakeFingerprint(r);
  };
  for (int i = 0; i < fingerprints; ++i) {
    s.stored.push_back(scan());
    s.matcher.Add(s.stored.back());
  }
  s.query = scan();
  return s;
}

void BM_WifiBestIndexed(benchmark::State& state) {
  Setup s = Make(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  for (auto _ : state) benchmark::DoNotOptimize(s.matcher.Best(s.query));
}
BENCHMARK(BM_WifiBestIndexed)
    ->Args({10000, 230})
    ->Args({10000, 20000})
    ->Unit(benchmark::kMicrosecond);

// A revisit: stored fingerprint k (third argument) heard again with 3 dB of noise and one AP
// missed, the common query of a run (a new place is the one above). Best prunes fingerprints
// that lack the query's strongest APs once it has met a good match: from the block of ids
// holding k on (these synthetic places have random RSSI, so other places never score well).
// A revisit of stored fingerprint `id`: its readings with 3 dB noise, one AP missed.
sensors::Fingerprint Revisit(const Setup& s, size_t id) {
  Random rng(11);
  sensors::Fingerprint q = s.stored[id];
  for (float& rssi : q.rssi_dbm) rssi += static_cast<float>(rng.Gaussian(0, 3));
  q.ap_ids.pop_back();
  q.rssi_dbm.pop_back();
  return q;
}

void BM_WifiBestRevisit(benchmark::State& state) {
  Setup s = Make(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const sensors::Fingerprint q = Revisit(s, static_cast<size_t>(state.range(2)));
  for (auto _ : state) benchmark::DoNotOptimize(s.matcher.Best(q));
}
BENCHMARK(BM_WifiBestRevisit)
    ->Args({10000, 230, 100})
    ->Args({10000, 230, 7000})
    ->Args({10000, 20000, 7000})
    ->Unit(benchmark::kMicrosecond);

// What the front ends ask (eqs. 9 and 12): the best match only if it reaches t_wifi (0.25), so
// the pruning has its budget from the start. A new place (above) and the revisit of id 7000.
void BM_WifiBestAtThreshold(benchmark::State& state) {
  Setup s = Make(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const sensors::Fingerprint q =
      state.range(2) >= 0 ? Revisit(s, static_cast<size_t>(state.range(2))) : s.query;
  const double t = s.matcher.options().match_threshold;
  for (auto _ : state) benchmark::DoNotOptimize(s.matcher.Best(q, nullptr, t));
}
BENCHMARK(BM_WifiBestAtThreshold)
    ->Args({10000, 230, -1})
    ->Args({10000, 20000, -1})
    ->Args({10000, 230, 7000})
    ->Unit(benchmark::kMicrosecond);

void BM_WifiBestPairwiseBaseline(benchmark::State& state) {
  Setup s = Make(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  for (auto _ : state) {
    double best = 0.0;
    for (const sensors::Fingerprint& f : s.stored)
      best = std::max(best, s.matcher.Weight(s.query, f));
    benchmark::DoNotOptimize(best);
  }
}
BENCHMARK(BM_WifiBestPairwiseBaseline)
    ->Args({10000, 230})
    ->Args({10000, 20000})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace ratslam

BENCHMARK_MAIN();
