#include "sensors/wifi_fingerprint_matcher.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/random.h"

namespace ratslam::sensors {
namespace {

using Readings = std::vector<std::pair<std::string, double>>;

TEST(WifiMatcherOptionsTest, DefaultsAreValid) {
  std::string error;
  EXPECT_TRUE(WifiMatcherOptions().IsValid(&error)) << error;
}

TEST(WifiFingerprintMatcherTest, ScanComparedWithItselfScoresOne) {
  WifiFingerprintMatcher m({});
  const Fingerprint f = m.MakeFingerprint({{"a", -40}, {"b", -71}, {"c", -88}});
  EXPECT_DOUBLE_EQ(m.Weight(f, f), 1.0);
  m.Add(f);
  EXPECT_DOUBLE_EQ(m.Best(f).weight, 1.0);
  EXPECT_EQ(m.Best(f).id, 0);
}

// Worked by hand with sigma^2 = 20 (2 sigma^2 = 40), P(s) = 0.1 * (s + 90):
// common A (diff 2) and B (diff 4): w_hit^(1/2) = exp(-(4 + 16) / 40 / 2) = exp(-0.25);
// extra C at -70: P = 2, exp(-4/40) = exp(-0.1); missing D at -80: P = 1, exp(-1/40);
// H / (H + E + M) = 2 / 4. So w = 0.5 exp(-0.375).
TEST(WifiFingerprintMatcherTest, Equation6WorkedExample) {
  WifiFingerprintMatcher m({});
  const Fingerprint q = m.MakeFingerprint({{"A", -50}, {"B", -60}, {"C", -70}});
  const Fingerprint j = m.MakeFingerprint({{"A", -52}, {"B", -64}, {"D", -80}});
  EXPECT_NEAR(m.Weight(q, j), 0.5 * std::exp(-0.375), 1e-12);
  m.Add(j);
  EXPECT_NEAR(m.Weights(q)[0], 0.5 * std::exp(-0.375), 1e-12);
}

// Offset-invariant eq. 3, the worked example again: differences 2 and 4 have mean 3, so the hit
// term sums (2-3)^2 + (4-3)^2 = 2 instead of 20: w = 0.5 exp(-2/40/2 - 0.1 - 0.025). The indexed
// path must agree with the pairwise one, and a scan 7 dB below a stored one scores as the stored
// one itself does on the shared APs (only the penalties of eqs. 4-5 see absolute RSSI).
TEST(WifiFingerprintMatcherTest, OffsetInvariantHitTermWorkedExample) {
  WifiMatcherOptions options;
  options.offset_invariant = true;
  WifiFingerprintMatcher m(options);
  const Fingerprint q = m.MakeFingerprint({{"A", -50}, {"B", -60}, {"C", -70}});
  const Fingerprint j = m.MakeFingerprint({{"A", -52}, {"B", -64}, {"D", -80}});
  const double expected = 0.5 * std::exp(-2.0 / 40.0 / 2.0 - 0.1 - 0.025);
  EXPECT_NEAR(m.Weight(q, j), expected, 1e-12);
  m.Add(j);
  EXPECT_NEAR(m.Weights(q)[0], expected, 1e-12);
  const Fingerprint stored = m.MakeFingerprint({{"a", -50}, {"b", -60}, {"c", -70}});
  const Fingerprint quieter = m.MakeFingerprint({{"a", -57}, {"b", -67}, {"c", -77}});
  EXPECT_NEAR(m.Weight(quieter, stored), 1.0, 1e-12);
  WifiFingerprintMatcher plain({});
  EXPECT_LT(plain.Weight(plain.MakeFingerprint({{"a", -57}, {"b", -67}, {"c", -77}}),
                         plain.MakeFingerprint({{"a", -50}, {"b", -60}, {"c", -70}})),
            0.5);
}

TEST(WifiFingerprintMatcherTest, MissingStrongApCostsMoreThanMissingWeakAp) {
  WifiFingerprintMatcher m({});
  const Fingerprint stored =
      m.MakeFingerprint({{"a", -50}, {"b", -60}, {"strong", -40}, {"weak", -88}});
  const Fingerprint without_strong = m.MakeFingerprint({{"a", -50}, {"b", -60}, {"weak", -88}});
  const Fingerprint without_weak = m.MakeFingerprint({{"a", -50}, {"b", -60}, {"strong", -40}});
  EXPECT_LT(m.Weight(without_strong, stored), m.Weight(without_weak, stored));
  // Likewise for an extra AP in the query.
  const Fingerprint base = m.MakeFingerprint({{"a", -50}, {"b", -60}});
  EXPECT_LT(m.Weight(m.MakeFingerprint({{"a", -50}, {"b", -60}, {"x", -45}}), base),
            m.Weight(m.MakeFingerprint({{"a", -50}, {"b", -60}, {"y", -89}}), base));
}

TEST(WifiFingerprintMatcherTest, RepeatedApsAndOrderDoNotMatter) {
  WifiFingerprintMatcher m({});
  const Fingerprint a = m.MakeFingerprint({{"b", -60}, {"a", -50}, {"b", -62}});
  const Fingerprint b = m.MakeFingerprint({{"a", -50}, {"b", -61}});
  EXPECT_EQ(a.ap_ids, b.ap_ids);
  EXPECT_EQ(a.rssi_dbm, b.rssi_dbm);
  EXPECT_DOUBLE_EQ(m.Weight(a, b), 1.0);
  const Fingerprint bad = m.MakeFingerprint({{"a", std::nan("")}, {"b", -150}, {"", -40}});
  EXPECT_TRUE(bad.empty());
}

TEST(WifiFingerprintMatcherTest, NoSharedApScoresZero) {
  WifiFingerprintMatcher m({});
  m.Add(m.MakeFingerprint({{"a", -50}}));
  const Fingerprint q = m.MakeFingerprint({{"z", -50}});
  EXPECT_EQ(m.Best(q).id, -1);
  EXPECT_EQ(m.Weights(q)[0], 0.0);
}

// The inverted index computes the same weights as the direct pairwise formula.
TEST(WifiFingerprintMatcherTest, IndexedWeightsEqualDirectWeights) {
  for (const bool neutral : {false, true}) {
    WifiMatcherOptions options;
    options.unmapped_aps_neutral = neutral;
    WifiFingerprintMatcher m(options);
    Random rng(11);
    // Stored scans hear APs 0-199, queries 0-259: some query APs are in no stored fingerprint.
    auto random_scan = [&](int universe) {
      Readings r;
      const int n = 5 + static_cast<int>(rng.Uniform() * 30);
      for (int i = 0; i < n; ++i) {
        r.push_back({"ap" + std::to_string(static_cast<int>(rng.Uniform() * universe)),
                     rng.Uniform(-95, -30)});
      }
      return m.MakeFingerprint(r);
    };
    std::vector<Fingerprint> stored;
    for (int i = 0; i < 300; ++i) {
      stored.push_back(random_scan(200));
      m.Add(stored.back());
    }
    for (int k = 0; k < 20; ++k) {
      const Fingerprint q = random_scan(260);
      const std::vector<double> indexed = m.Weights(q);
      for (size_t i = 0; i < stored.size(); ++i) {
        ASSERT_NEAR(indexed[i], m.Weight(q, stored[i]), 1e-9 * std::max(1.0, indexed[i]));
      }
    }
    WifiFingerprintMatcher restored(options);
    ASSERT_TRUE(restored.SetState(m.state()).ok());
    const Fingerprint q = stored[17];
    EXPECT_EQ(restored.Best(q).id, m.Best(q).id);
  }
}

// Worked example: stored A = {a -50, b -60}, B = {c -50}. The query hears A's APs exactly and a
// new AP n at -40 that nothing stored holds. Eq. 4 charges n P = 0.1 * (-40 + 90) = 5, P^2 = 25,
// over 2 sigma^2 = 40: w_A = exp(-0.625) * 2 / 3 = 0.3568. With unmapped_aps_neutral n is left
// out: w_A = 2 / 2 = 1. A stored AP the query misses still costs eq. 5 either way: the query
// {a -50} against A misses b (P = 3, P^2 = 9): w = exp(-9 / 40) * 1 / 2 = 0.3993.
TEST(WifiFingerprintMatcherTest, UnmappedApsNeutralWorkedExample) {
  for (const bool neutral : {false, true}) {
    WifiMatcherOptions options;
    options.unmapped_aps_neutral = neutral;
    WifiFingerprintMatcher m(options);
    const Fingerprint a = m.MakeFingerprint({{"a", -50}, {"b", -60}});
    m.Add(a);
    m.Add(m.MakeFingerprint({{"c", -50}}));
    const Fingerprint q = m.MakeFingerprint({{"a", -50}, {"b", -60}, {"n", -40}});
    const double expected = neutral ? 1.0 : std::exp(-25.0 / 40.0) * 2.0 / 3.0;
    EXPECT_NEAR(m.Weights(q)[0], expected, 1e-12) << neutral;
    EXPECT_NEAR(m.Best(q).weight, expected, 1e-12) << neutral;
    const Fingerprint partial = m.MakeFingerprint({{"a", -50}});
    EXPECT_NEAR(m.Weights(partial)[0], std::exp(-9.0 / 40.0) / 2.0, 1e-12) << neutral;
  }
}

// FollowRevisit makes a stored fingerprint follow the scan's APs and keeps the index exact:
// afterwards the indexed weights equal the pairwise formula on the updated fingerprint, and a
// matcher restored from the state (re-indexed from scratch) gives the same weights to the bit.
TEST(WifiFingerprintMatcherTest, FollowRevisitAddsNewAndDropsGoneApsAndKeepsTheIndexExact) {
  WifiFingerprintMatcher m({});
  const Fingerprint a = m.MakeFingerprint({{"a", -50}, {"c", -70}, {"f", -95}});
  m.Add(m.MakeFingerprint({{"b", -60}, {"c", -65}}));
  m.Add(a);
  m.Add(m.MakeFingerprint({{"a", -55}, {"d", -80}}));
  // The scan hears a (at another RSSI: the template keeps -50), misses c (-70, above the
  // penalty floor of -90: dropped) and f (-95, below it: kept), and hears new e and d.
  const Fingerprint scan = m.MakeFingerprint({{"a", -45}, {"e", -58}, {"d", -75}});
  const WifiFingerprintMatcher::Update u = m.FollowRevisit(1, scan);
  EXPECT_EQ(u.added, 2u);
  EXPECT_EQ(u.dropped, 1u);
  const Fingerprint& updated = m.state().fingerprints[1];
  const Fingerprint expected = m.MakeFingerprint({{"a", -50}, {"f", -95}, {"e", -58}, {"d", -75}});
  EXPECT_EQ(updated.ap_ids, expected.ap_ids);
  EXPECT_EQ(updated.rssi_dbm, expected.rssi_dbm);
  const WifiFingerprintMatcher::Update again = m.FollowRevisit(1, scan);  // nothing left to do
  EXPECT_EQ(again.added + again.dropped, 0u);
  WifiFingerprintMatcher restored({});
  ASSERT_TRUE(restored.SetState(m.state()).ok());
  for (const Fingerprint& q : {scan, a, m.MakeFingerprint({{"c", -70}, {"e", -60}})}) {
    const std::vector<double> w = m.Weights(q);
    for (uint32_t i = 0; i < m.size(); ++i) {
      EXPECT_NEAR(w[i], m.Weight(q, m.state().fingerprints[i]), 1e-12) << i;
    }
    EXPECT_EQ(w, restored.Weights(q));
    EXPECT_EQ(m.Best(q).id, restored.Best(q).id);
    EXPECT_EQ(m.Best(q).weight, restored.Best(q).weight);
  }
  // c's posting for the template is gone: a scan hearing only c no longer reaches it.
  EXPECT_EQ(m.Weights(m.MakeFingerprint({{"c", -70}}))[1], 0.0);
  // The scan now matches the template better than before.
  WifiFingerprintMatcher before({});
  before.Add(before.MakeFingerprint({{"a", -50}, {"c", -70}, {"f", -95}}));
  const double w_before =
      before.Weights(before.MakeFingerprint({{"a", -45}, {"e", -58}, {"d", -75}}))[0];
  EXPECT_GT(m.Weights(scan)[1], w_before);
}

// Best, which skips the exp of fingerprints whose penalties alone rule them out, scans the index
// in blocks of ids and, once a good match is known, scores only fingerprints holding one of the
// query's most penalised APs (the pruning that revisits trigger), returns exactly the exhaustive
// argmax of the weights (largest weight, ties to the lower id): against the pairwise formula on
// every stored fingerprint, in one building (every fingerprint shares APs: the blocked scan) and on
// a campus (few do), with and without the offset-invariant hit term, over more fingerprints than
// one block.
TEST(WifiFingerprintMatcherTest, BestIsTheExhaustiveArgmax) {
  for (const int universe : {60, 5000}) {
    for (const bool offset_invariant : {false, true}) {
      WifiMatcherOptions options;
      options.offset_invariant = offset_invariant;
      options.unmapped_aps_neutral = offset_invariant;  // both paths, and unmapped APs below
      WifiFingerprintMatcher m(options);
      Random rng(universe + offset_invariant);
      auto scan = [&]() {
        const int center = static_cast<int>(rng.Uniform() * universe);
        Readings r;
        for (int i = 0; i < 25; ++i) {
          const int ap = (center + static_cast<int>(rng.Gaussian(0, 8)) + universe) % universe;
          r.push_back({"ap" + std::to_string(ap), rng.Uniform(-92, -35)});
        }
        return m.MakeFingerprint(r);
      };
      std::vector<Fingerprint> stored;
      for (int i = 0; i < 1500; ++i) {
        stored.push_back(scan());
        m.Add(stored.back());
      }
      // Exact duplicates of stored fingerprints: ties, which must go to the first copy.
      for (int i = 0; i < 20; ++i) m.Add(stored[static_cast<size_t>(i * 37)]);
      for (int k = 0; k < 60; ++k) {
        // Copies of stored fingerprints, noisy revisits (3 dB, one AP lost) and new places.
        Fingerprint q = k % 3 == 2 ? scan() : stored[static_cast<size_t>(k * 37 % 1500)];
        if (k % 3 == 1) {
          for (float& rssi : q.rssi_dbm) rssi += static_cast<float>(rng.Gaussian(0, 3));
          q.ap_ids.erase(q.ap_ids.begin());
          q.rssi_dbm.erase(q.rssi_dbm.begin());
        }
        int32_t expected_id = -1;
        double expected = 0.0;
        for (uint32_t i = 0; i < m.size(); ++i) {
          const double w = m.Weight(q, m.state().fingerprints[i]);
          if (w > expected) {
            expected = w;
            expected_id = static_cast<int32_t>(i);
          }
        }
        const WifiMatch best = m.Best(q);
        ASSERT_EQ(best.id, expected_id) << "universe " << universe << " query " << k;
        ASSERT_NEAR(best.weight, expected, 1e-12);
        // The indexed weights agree with Best to the bit.
        ASSERT_EQ(best.weight, m.Weights(q)[static_cast<size_t>(best.id)]);
        // With a floor (the pruning's budget from the start): the same answer when the best
        // reaches it, at t_wifi and exactly at the best weight, and nothing just above it.
        const WifiMatch at_t = m.Best(q, nullptr, options.match_threshold);
        if (expected >= options.match_threshold) {
          ASSERT_EQ(at_t.id, best.id) << "universe " << universe << " query " << k;
          ASSERT_EQ(at_t.weight, best.weight);
        } else {
          ASSERT_EQ(at_t.id, -1) << "universe " << universe << " query " << k;
          ASSERT_EQ(at_t.weight, 0.0);
        }
        ASSERT_EQ(m.Best(q, nullptr, best.weight).id, best.id);
        ASSERT_EQ(m.Best(q, nullptr, std::nextafter(best.weight, 2.0)).id, -1);
      }
    }
  }
}

// The pruning's edge: the winner lacks the query's most penalised AP. A (id 0, the first block of
// ids) holds every query AP at 6 dB off: w = exp(-36 / 40) = 0.41. B (id 600, the second block)
// holds the ten weak APs exactly but not x (-40 dBm, P^2 = 25): w = exp(-25 / 40) 10 / 11 = 0.49.
// After the first block the budget is 40 ln(1 / 0.41) = 36 of penalty, so x alone (25) does not
// rule out B; the essential lists are x and five weak APs, and B is on those. Filler fingerprints
// (a weak query AP and a strong AP of their own) make the index scan in blocks.
TEST(WifiFingerprintMatcherTest, PruningKeepsAWinnerThatLacksTheStrongestAp) {
  WifiFingerprintMatcher m{WifiMatcherOptions()};
  Readings query = {{"x", -40}}, a, b;
  for (int k = 0; k < 10; ++k) {
    std::string ap = "a";  // (not "a" + ...: GCC 12's -Wrestrict false positive)
    ap += std::to_string(k);
    query.push_back({ap, -75});
    a.push_back({ap, -81});
    b.push_back({ap, -75});
  }
  a.push_back({"x", -46});
  m.Add(m.MakeFingerprint(a));
  for (int i = 1; i < 700; ++i) {
    if (i == 600) {
      m.Add(m.MakeFingerprint(b));
    } else {
      std::string own = "own";
      own += std::to_string(i);
      m.Add(m.MakeFingerprint({{"a0", -99}, {own, -40}}));
    }
  }
  const Fingerprint q = m.MakeFingerprint(query);
  const std::vector<double> w = m.Weights(q);
  EXPECT_NEAR(w[0], std::exp(-0.9), 1e-12);
  EXPECT_NEAR(w[600], std::exp(-25.0 / 40.0) * 10.0 / 11.0, 1e-12);
  const WifiMatch best = m.Best(q);
  EXPECT_EQ(best.id, 600);
  EXPECT_EQ(best.weight, w[600]);
  // A floor of 0.45 gives the pruning a budget of 40 ln(1 / 0.45) = 31.9 from the first block:
  // x (25) alone still does not rule B out. Above B's weight nothing is left.
  EXPECT_EQ(m.Best(q, nullptr, 0.45).id, 600);
  EXPECT_EQ(m.Best(q, nullptr, 0.45).weight, w[600]);
  EXPECT_EQ(m.Best(q, nullptr, 0.5).id, -1);
}

}  // namespace
}  // namespace ratslam::sensors
