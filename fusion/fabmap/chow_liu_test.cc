#include "fusion/fabmap/chow_liu.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <utility>

#include "common/random.h"
#include "fusion/fabmap/synthetic_words.h"

namespace ratslam::fabmap {
namespace {

TEST(MutualInformationTest, KnownValues) {
  EXPECT_NEAR(MutualInformation(100, 50, 50, 25), 0.0, 1e-12);            // independent
  EXPECT_NEAR(MutualInformation(100, 50, 50, 50), std::log(2.0), 1e-12);  // identical
  EXPECT_NEAR(MutualInformation(100, 50, 50, 0), std::log(2.0), 1e-12);   // complementary
  // One hand-computed asymmetric case: n=4, a on in 2, b on in 1, together 1.
  // p11=1/4 (pa pb = 1/8), p10=1/4 (pa (1-pb) = 3/8), p01=0, p00=1/2 (3/8).
  const double expected =
      0.25 * std::log(2.0) + 0.25 * std::log(2.0 / 3.0) + 0.5 * std::log(4.0 / 3.0);
  EXPECT_NEAR(MutualInformation(4, 2, 1, 1), expected, 1e-12);
}

std::set<std::pair<WordId, WordId>> Edges(const ChowLiuTree& tree) {
  std::set<std::pair<WordId, WordId>> edges;
  for (WordId q = 0; q < tree.size(); ++q) {
    if (tree.parent[q] != ChowLiuTree::kNoParent) {
      edges.insert({std::min(q, tree.parent[q]), std::max(q, tree.parent[q])});
    }
  }
  return edges;
}

TEST(ChowLiuTest, RecoversPlantedDependencies) {
  // Words 1, 2 copy word 0 (with 5% flips), 6 copies 5; the rest are independent.
  Random random(7);
  std::vector<Observation> observations;
  for (int i = 0; i < 2000; ++i) {
    bool on[8];
    for (bool& b : on) b = random.Uniform() < 0.3;
    auto noisy = [&](bool b) { return random.Uniform() < 0.05 ? !b : b; };
    on[1] = noisy(on[0]);
    on[2] = noisy(on[1]);
    on[6] = noisy(on[5]);
    Observation o;
    for (WordId q = 0; q < 8; ++q) {
      if (on[q]) o.push_back(q);
    }
    observations.push_back(o);
  }
  const auto tree = LearnChowLiuTree(observations, 8);
  ASSERT_TRUE(tree.ok()) << tree.status().message();
  const auto edges = Edges(*tree);
  EXPECT_EQ(edges.size(), 7u);  // a spanning tree of 8 words
  EXPECT_TRUE(edges.count({0, 1}));
  EXPECT_TRUE(edges.count({1, 2}));
  EXPECT_TRUE(edges.count({5, 6}));
  EXPECT_FALSE(edges.count({0, 2}));  // explained through word 1

  // Conditionals follow the planted copy: p(z_2 = 1 | z_1 = 1) ~ 0.95.
  const WordId child = tree->parent[2] == 1 ? 2 : 1;
  EXPECT_NEAR(tree->on_given_parent_on[child], 0.95, 0.03);
  EXPECT_NEAR(tree->on_given_parent_off[child], 0.05, 0.03);
}

TEST(ChowLiuTest, SyntheticWorldPairsAreLinked) {
  SyntheticWordWorld world;
  world.vocabulary_size = 400;
  world.mean_words_per_observation = 40;
  Random random(3);
  std::vector<Observation> observations;
  for (int i = 0; i < 800; ++i) {
    observations.push_back(world.Observe(world.SamplePlace(&random), &random));
  }
  const auto tree = LearnChowLiuTree(observations, world.vocabulary_size);
  ASSERT_TRUE(tree.ok());
  const auto edges = Edges(*tree);
  int linked = 0;
  for (WordId q = 1; q < world.vocabulary_size; q += 2) linked += edges.count({q - 1, q});
  EXPECT_GT(linked, 190);  // of 200 planted pairs
}

TEST(ChowLiuTest, RejectsBadInput) {
  EXPECT_FALSE(LearnChowLiuTree({}, 10).ok());
  EXPECT_FALSE(LearnChowLiuTree({{1, 2}}, 0).ok());
  const auto out_of_range = LearnChowLiuTree({{1, 12}}, 10);
  ASSERT_FALSE(out_of_range.ok());
  EXPECT_NE(out_of_range.status().message().find("observation 0"), std::string::npos);
  EXPECT_FALSE(LearnChowLiuTree({{3, 1}}, 10).ok());  // not sorted
  ChowLiuOptions bad;
  bad.pseudo_count = 0.0;
  EXPECT_FALSE(LearnChowLiuTree({{1}}, 10, bad).ok());
  std::string error;
  EXPECT_TRUE(ChowLiuOptions{}.IsValid(&error));
}

TEST(ChowLiuTest, NormaliseObservationSortsAndChecks) {
  Observation o = {5, 1, 5, 3};
  ASSERT_TRUE(NormaliseObservation(&o, 6, "x").ok());
  EXPECT_EQ(o, (Observation{1, 3, 5}));
  Observation bad = {7};
  EXPECT_FALSE(NormaliseObservation(&bad, 6, "x").ok());
}

TEST(ChowLiuTest, JoinForestOffsetsTheSecondTree) {
  const auto a = LearnChowLiuTree({{0, 1}, {1}, {0, 1, 2}}, 3);
  const auto b = LearnChowLiuTree({{0}, {1}, {0, 1}}, 2);
  ASSERT_TRUE(a.ok() && b.ok());
  const ChowLiuTree joined = JoinForest(*a, *b);
  ASSERT_EQ(joined.size(), 5u);
  int roots = 0;
  for (WordId q = 0; q < 5; ++q) {
    if (joined.parent[q] == ChowLiuTree::kNoParent) {
      ++roots;
    } else {
      EXPECT_EQ(q < 3, joined.parent[q] < 3);  // no edge between the two trees
    }
  }
  EXPECT_EQ(roots, 2);
  EXPECT_DOUBLE_EQ(joined.marginal[4], b->marginal[1]);
  std::vector<uint32_t> begin;
  std::vector<WordId> children;
  joined.ChildLists(&begin, &children);
  EXPECT_EQ(children.size(), 3u);
}

}  // namespace
}  // namespace ratslam::fabmap
