#include "fusion/fabmap/fabmap.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/random.h"
#include "fusion/fabmap/synthetic_words.h"

namespace ratslam::fabmap {
namespace {

struct World {
  SyntheticWordWorld words;
  ChowLiuTree tree;
  std::vector<Observation> samples;
};

World MakeWorld(uint32_t vocabulary, double mean_words, uint64_t seed) {
  World w;
  w.words.vocabulary_size = vocabulary;
  w.words.mean_words_per_observation = mean_words;
  Random random(seed);
  std::vector<Observation> training;
  for (int i = 0; i < 500; ++i) {
    training.push_back(w.words.Observe(w.words.SamplePlace(&random), &random));
  }
  w.tree = *LearnChowLiuTree(training, vocabulary);
  for (int i = 0; i < 300; ++i) {
    w.samples.push_back(w.words.Observe(w.words.SamplePlace(&random), &random));
  }
  return w;
}

FabmapModel MakeModel(const World& w, UnknownWorld unknown = UnknownWorld::kMeanField,
                      double p_detect = 0.8) {
  FabmapOptions options;
  options.unknown_world = unknown;
  DetectorBlock block;
  block.count = w.tree.size();
  block.detector.p_observed_given_exists = p_detect;
  auto model = FabmapModel::Create(w.tree, {block}, w.samples, options);
  EXPECT_TRUE(model.ok()) << model.status().message();
  return *std::move(model);
}

TEST(FabmapTest, SparseLikelihoodEqualsDenseOracle) {
  const World w = MakeWorld(300, 30, 1);
  for (double p_absent : {0.0, 0.05}) {
    FabmapOptions options;
    DetectorBlock block;
    block.count = w.tree.size();
    block.detector.p_observed_given_exists = 0.39;  // openFABMAP defaults
    block.detector.p_observed_given_absent = p_absent;
    auto model = *FabmapModel::Create(w.tree, {block}, w.samples, options);
    Random random(11);
    for (int i = 0; i < 40; ++i) {
      // Random places, including empty ones and ones of random words (not from the world).
      Observation o;
      if (i % 2 == 0) {
        o = w.words.Observe(w.words.SamplePlace(&random), &random);
      } else {
        for (int k = 0; k < i; ++k) o.push_back(static_cast<WordId>(random.NextU64() % 300));
      }
      ASSERT_TRUE(model.AddPlace(o).ok());
    }
    for (int trial = 0; trial < 20; ++trial) {
      Observation z;
      for (int k = 0; k < trial * 3; ++k) z.push_back(static_cast<WordId>(random.NextU64() % 300));
      ASSERT_TRUE(NormaliseObservation(&z, 300, "query").ok());
      std::vector<double> sparse;
      model.LogLikelihoods(z, &sparse);
      ASSERT_EQ(sparse.size(), model.places());
      for (uint32_t place = 0; place < model.places(); ++place) {
        const double dense = model.DenseLogLikelihood(z, place);
        EXPECT_NEAR(sparse[place], dense, 1e-9 * std::abs(dense) + 1e-9);
      }
    }
  }
}

// The formula of fabmap.h worked by hand for two words (not from the code's tables): word 0 is the
// root with p(z0) = 0.5; word 1 hangs off it with p(z1) = 0.4, p(z1 | z0) = 0.7; detector
// PzGe = 0.8, PzGNe = 0.1. Existence priors: (0.5 - 0.1) / 0.7 = 4/7 and (0.4 - 0.1) / 0.7 = 3/7.
// Query Z = {0, 1}.
// Word 0 at a place that saw it: p(e0 | seen) = 0.8 (4/7) / (0.8 (4/7) + 0.1 (3/7)) = 32/35.
//   p(z0=1 | e0=1) = beta / (alpha + beta) with alpha = 0.5 * 0.2 * 0.5, beta = 0.5 * 0.8 * 0.5:
//   0.8; p(z0=1 | e0=0): alpha = 0.5 * 0.9 * 0.5, beta = 0.5 * 0.1 * 0.5: 0.1.
//   Term: 0.8 (32/35) + 0.1 (3/35) = 37/50.
// Word 1 given z0 = 1: p(z1=1 | e1=1): alpha = 0.4 * 0.2 * 0.3, beta = 0.6 * 0.8 * 0.7: 14/15;
//   p(z1=1 | e1=0): alpha = 0.4 * 0.9 * 0.3, beta = 0.6 * 0.1 * 0.7: 7/25.
//   A place that did not see it: p(e1 | not seen) = 0.2 (3/7) / (0.2 (3/7) + 0.9 (4/7)) = 1/7,
//   term (14/15)(1/7) + (7/25)(6/7) = 28/75. One that saw it: p(e1 | seen) = 6/7,
//   term (14/15)(6/7) + (7/25)(1/7) = 21/25.
TEST(FabmapTest, LikelihoodMatchesAHandWorkedExample) {
  ChowLiuTree tree;
  tree.parent = {ChowLiuTree::kNoParent, 0};
  tree.marginal = {0.5, 0.4};
  tree.on_given_parent_on = {0.5, 0.7};
  tree.on_given_parent_off = {0.5, 0.1};
  DetectorBlock block;
  block.count = 2;
  block.detector = {0.8, 0.1};
  auto model = FabmapModel::Create(tree, {block}, {{0}}, {});
  ASSERT_TRUE(model.ok()) << model.status().message();
  ASSERT_TRUE(model->AddPlace({0}).ok());     // place 0 saw word 0 only
  ASSERT_TRUE(model->AddPlace({0, 1}).ok());  // place 1 saw both
  std::vector<double> log_likelihood;
  model->LogLikelihoods({0, 1}, &log_likelihood);
  ASSERT_EQ(log_likelihood.size(), 2u);
  const double place0 = std::log(37.0 / 50.0) + std::log(28.0 / 75.0);
  const double place1 = std::log(37.0 / 50.0) + std::log(21.0 / 25.0);
  EXPECT_NEAR(log_likelihood[0], place0, 1e-12);
  EXPECT_NEAR(log_likelihood[1], place1, 1e-12);
  EXPECT_NEAR(model->DenseLogLikelihood({0, 1}, 0), place0, 1e-12);
  EXPECT_NEAR(model->DenseLogLikelihood({0, 1}, 1), place1, 1e-12);
}

TEST(FabmapTest, LikelihoodIsANormalisedDistributionOverObservations) {
  // Summing p(Z | L) over all 2^V observations of a tiny vocabulary gives 1.
  const ChowLiuTree tree = *LearnChowLiuTree({{0, 1}, {1, 2}, {0, 1, 3}, {2}, {0, 3}}, 4);
  DetectorBlock block;
  block.count = 4;
  block.detector.p_observed_given_absent = 0.02;
  auto model = *FabmapModel::Create(tree, {block}, {{0}, {1, 2}}, FabmapOptions{});
  ASSERT_TRUE(model.AddPlace({0, 2}).ok());
  double total = 0.0;
  for (int bits = 0; bits < 16; ++bits) {
    Observation z;
    for (WordId q = 0; q < 4; ++q) {
      if (bits & (1 << q)) z.push_back(q);
    }
    total += std::exp(model.DenseLogLikelihood(z, 0));
  }
  EXPECT_NEAR(total, 1.0, 1e-9);
}

TEST(FabmapTest, IdenticalObservationMatchesItsPlace) {
  const World w = MakeWorld(1000, 50, 2);
  FabmapModel model = MakeModel(w);
  Random random(5);
  std::vector<Observation> places;
  for (int i = 0; i < 300; ++i) {
    places.push_back(w.words.Observe(w.words.SamplePlace(&random), &random));
    ASSERT_TRUE(model.AddPlace(places.back()).ok());
  }
  for (uint32_t i : {0u, 17u, 299u}) {
    const LocalisationResult r = model.Localise(places[i]);
    EXPECT_EQ(r.best_place, i);
    EXPECT_GT(r.best_probability, 0.99);
    EXPECT_LT(r.new_place_probability, 0.01);
  }
}

TEST(FabmapTest, AllNewObservationIsRejected) {
  const World w = MakeWorld(1000, 50, 3);
  FabmapModel model = MakeModel(w);
  Random random(6);
  for (int i = 0; i < 300; ++i) {
    ASSERT_TRUE(model.AddPlace(w.words.Observe(w.words.SamplePlace(&random), &random)).ok());
  }
  int rejected = 0;
  for (int i = 0; i < 100; ++i) {
    const LocalisationResult r =
        model.Localise(w.words.Observe(w.words.SamplePlace(&random), &random));
    rejected += r.best_place < 0;
  }
  EXPECT_GE(rejected, 95);
}

// Revisits (a second observation of a mapped place) are recognised and truly new places are
// still called new with 10,000 places in the map: p(new) stays calibrated as the map grows.
TEST(FabmapTest, NewPlaceStaysCalibratedAtTenThousandPlaces) {
  const World w = MakeWorld(1000, 50, 4);
  FabmapModel model = MakeModel(w);
  FabmapModel sampled = MakeModel(w, UnknownWorld::kSampled);
  Random random(8);
  std::vector<Observation> places;
  for (int i = 0; i < 10000; ++i) {
    places.push_back(w.words.SamplePlace(&random));
    const Observation seen = w.words.Observe(places.back(), &random);
    ASSERT_TRUE(model.AddPlace(seen).ok());
    ASSERT_TRUE(sampled.AddPlace(seen).ok());
  }
  int new_called_new = 0, sampled_new_called_new = 0, revisits_found = 0;
  const int queries = 200;
  for (int i = 0; i < queries; ++i) {
    const Observation fresh = w.words.Observe(w.words.SamplePlace(&random), &random);
    new_called_new += model.Localise(fresh).best_place < 0;
    sampled_new_called_new += sampled.Localise(fresh).best_place < 0;
    const uint32_t target = static_cast<uint32_t>(random.NextU64() % places.size());
    revisits_found += model.Localise(w.words.Observe(places[target], &random)).best_place ==
                      static_cast<int64_t>(target);
  }
  EXPECT_GE(new_called_new, queries * 95 / 100);
  EXPECT_GE(revisits_found, queries * 90 / 100);
  RecordProperty("mean_field_new_called_new", new_called_new);
  RecordProperty("sampled_new_called_new", sampled_new_called_new);
}

// Localise rules places out before their last words (fabmap.h); every number must still be the
// exhaustive one, to the bit: on revisits (one place stands out), new places (the new place wins
// and every place is ruled out), a map of near copies (too many places survive the bound, so the
// scatter goes on), both unknown-world estimates and the openFABMAP detector.
TEST(FabmapTest, RulingPlacesOutChangesNoNumber) {
  const World w = MakeWorld(2000, 100, 12);
  for (const UnknownWorld unknown : {UnknownWorld::kMeanField, UnknownWorld::kSampled}) {
    for (const double p_detect : {0.8, 0.39}) {
      FabmapModel model = MakeModel(w, unknown, p_detect);
      Random random(13);
      std::vector<Observation> places;
      for (int i = 0; i < 3000; ++i) {
        places.push_back(w.words.SamplePlace(&random));
        // A run of 200 observations of one place: near copies that all survive the bound.
        const Observation& truth = i >= 1000 && i < 1200 ? places[1000] : places.back();
        ASSERT_TRUE(model.AddPlace(w.words.Observe(truth, &random)).ok());
      }
      uint64_t ruled_out = 0;
      int queries = 0, early = 0;
      auto check = [&](const Observation& z) -> uint32_t {
        const LocalisationResult fast = model.Localise(z);
        const LocalisationResult slow = model.LocaliseExhaustive(z);
        EXPECT_EQ(fast.best_place, slow.best_place);
        EXPECT_EQ(fast.best_probability, slow.best_probability);
        EXPECT_EQ(fast.new_place_probability, slow.new_place_probability);
        EXPECT_EQ(fast.best_mapped_place, slow.best_mapped_place);
        EXPECT_EQ(fast.best_mapped_probability, slow.best_mapped_probability);
        EXPECT_EQ(fast.best_mapped_log_odds, slow.best_mapped_log_odds);
        EXPECT_TRUE(fast.place_probability == slow.place_probability);
        EXPECT_EQ(slow.places_ruled_out, 0u);
        EXPECT_LE(fast.words_summed_for_every_place, slow.words_summed_for_every_place);
        ruled_out += fast.places_ruled_out;
        ++queries;
        early += fast.words_summed_for_every_place < slow.words_summed_for_every_place / 2;
        return fast.places_ruled_out;
      };
      int revisits_mostly_ruled_out = 0, copies_none_ruled_out = 0, revisits_early = 0;
      for (int i = 0; i < 30; ++i) {
        check(w.words.Observe(w.words.SamplePlace(&random), &random));  // a new place
        const int before = early;
        revisits_mostly_ruled_out += check(w.words.Observe(places[random.NextU64() % 1000],
                                                           &random)) > model.places() * 9 / 10;
        revisits_early += early - before;
        copies_none_ruled_out += check(w.words.Observe(places[1000], &random)) == 0;
        ASSERT_FALSE(HasFailure());
      }
      check({});  // nothing observed
      // The bound did its work on revisits, most of them before half of the active words were
      // summed for every place, and the near copies took the other path.
      EXPECT_GE(revisits_mostly_ruled_out, 25) << ToString(unknown) << " " << p_detect;
      EXPECT_GE(revisits_early, 20) << ToString(unknown) << " " << p_detect;
      EXPECT_GE(copies_none_ruled_out, 25) << ToString(unknown) << " " << p_detect;
      RecordProperty("mean_ruled_out_" + ToString(unknown), static_cast<int>(ruled_out / queries));
    }
  }
}

// The index keeps places in blocks of 2^16 (a posting is a 16-bit number within its block),
// scored in stripes of 2^13: places past the first block and on either side of every stripe's
// edge get the dense oracle's likelihood, a revisit of one is found, and Localise still equals
// the exhaustive sum across blocks.
TEST(FabmapTest, PlacesPastTheFirstIndexBlockAreScoredLikeTheOthers) {
  const World w = MakeWorld(400, 12, 21);
  FabmapModel model = MakeModel(w);
  Random random(22);
  std::vector<Observation> places;
  const uint32_t n = (1u << 16) + 5000;
  for (uint32_t i = 0; i < n; ++i) {
    places.push_back(w.words.SamplePlace(&random));
    ASSERT_TRUE(model.AddPlace(w.words.Observe(places.back(), &random)).ok());
  }
  std::vector<double> sparse;
  for (uint32_t target : {3u, 65535u, 65536u, 65537u, n - 1}) {
    const Observation z = w.words.Observe(places[target], &random);
    model.LogLikelihoods(z, &sparse);
    ASSERT_EQ(sparse.size(), n);
    std::vector<uint32_t> checked = {0u, n - 1, target};
    for (uint32_t edge = 1u << 12; edge < n; edge += 1u << 12) {
      for (uint32_t place = edge - 2; place < edge + 2; ++place) checked.push_back(place);
    }
    for (uint32_t place : checked) {
      const double dense = model.DenseLogLikelihood(z, place);
      EXPECT_NEAR(sparse[place], dense, 1e-9 * std::abs(dense) + 1e-9) << place;
    }
    const LocalisationResult fast = model.Localise(z);
    const LocalisationResult slow = model.LocaliseExhaustive(z);
    EXPECT_EQ(fast.best_mapped_place, slow.best_mapped_place);
    EXPECT_EQ(fast.best_mapped_log_odds, slow.best_mapped_log_odds);
    EXPECT_TRUE(fast.place_probability == slow.place_probability);
    // 12 words of 400 do not single a place out of 70k, but the place seen must be among the
    // likeliest: its log-likelihood is above that of 99 % of the places.
    size_t above = 0;
    for (double s : sparse) above += s > sparse[target];
    EXPECT_LT(above, n / 100) << target;
  }
}

TEST(FabmapTest, LocaliseAmongCandidates) {
  const World w = MakeWorld(500, 40, 9);
  FabmapModel model = MakeModel(w);
  Random random(10);
  std::vector<Observation> places;
  for (int i = 0; i < 50; ++i) {
    places.push_back(w.words.Observe(w.words.SamplePlace(&random), &random));
    ASSERT_TRUE(model.AddPlace(places.back()).ok());
  }
  const LocalisationResult in = model.LocaliseAmong(places[7], {3, 7, 9});
  EXPECT_EQ(in.best_place, 7);
  ASSERT_EQ(in.place_probability.size(), 3u);
  EXPECT_GT(in.place_probability[1], 0.99);
  const LocalisationResult out = model.LocaliseAmong(places[7], {3, 9});
  EXPECT_EQ(out.best_place, -1);  // the true place is not a candidate: new
}

TEST(FabmapTest, RejectsBadConfiguration) {
  const World w = MakeWorld(100, 10, 12);
  DetectorBlock block;
  block.count = 100;
  FabmapOptions bad;
  bad.p_new_place = 1.0;
  EXPECT_FALSE(FabmapModel::Create(w.tree, {block}, w.samples, bad).ok());
  EXPECT_FALSE(FabmapModel::Create(w.tree, {block}, {}, FabmapOptions{}).ok());
  DetectorBlock short_block = block;
  short_block.count = 99;
  EXPECT_FALSE(FabmapModel::Create(w.tree, {short_block}, w.samples, FabmapOptions{}).ok());
  DetectorBlock bad_detector = block;
  bad_detector.detector.p_observed_given_absent = 0.5;
  EXPECT_FALSE(FabmapModel::Create(w.tree, {bad_detector}, w.samples, FabmapOptions{}).ok());
  auto model = *FabmapModel::Create(w.tree, {block}, w.samples, FabmapOptions{});
  EXPECT_FALSE(model.AddPlace({100}).ok());
  EXPECT_EQ(UnknownWorldFromString("sampled").value(), UnknownWorld::kSampled);
  EXPECT_FALSE(UnknownWorldFromString("bogus").ok());
  std::string error;
  EXPECT_TRUE(FabmapOptions{}.IsValid(&error));
  EXPECT_TRUE(DetectorModel{}.IsValid(&error));
}

}  // namespace
}  // namespace ratslam::fabmap
