#include "fusion/fabmap/vocabulary.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "common/random.h"
#include "dataset/image_loader.h"
#include "tests/test_paths.h"

namespace ratslam::fabmap {
namespace {

// Binary descriptors in `clusters` tight groups: each a random centre with a few bits flipped.
DescriptorSet ClusteredOrb(int clusters, int per_cluster, uint64_t seed,
                           std::vector<std::vector<uint8_t>>* centres) {
  Random random(seed);
  DescriptorSet set;
  set.kind = DescriptorKind::kOrb;
  set.length = 32;
  centres->clear();
  for (int c = 0; c < clusters; ++c) {
    std::vector<uint8_t> centre(32);
    for (auto& b : centre) b = static_cast<uint8_t>(random.NextU64());
    centres->push_back(centre);
  }
  for (int i = 0; i < per_cluster; ++i) {
    for (int c = 0; c < clusters; ++c) {
      std::vector<uint8_t> d = (*centres)[c];
      for (int flip = 0; flip < 3; ++flip) {
        const int bit = static_cast<int>(random.NextU64() % 256);
        d[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
      }
      set.binary.insert(set.binary.end(), d.begin(), d.end());
      ++set.count;
    }
  }
  return set;
}

TEST(VocabularyTest, KMajorityFindsBinaryClusters) {
  std::vector<std::vector<uint8_t>> centres;
  const DescriptorSet data = ClusteredOrb(8, 30, 1, &centres);
  VocabularyOptions options;
  options.words = 8;
  const auto v = Vocabulary::Train(data, options);
  ASSERT_TRUE(v.ok()) << v.status().message();
  // Every true centre maps to its own word: 8 distinct words.
  DescriptorSet queries;
  queries.kind = DescriptorKind::kOrb;
  queries.length = 32;
  for (const auto& c : centres) {
    queries.binary.insert(queries.binary.end(), c.begin(), c.end());
    ++queries.count;
  }
  EXPECT_EQ(v->Quantise(queries).size(), 8u);
  // Seeded: the same seed gives the same bytes.
  EXPECT_EQ(Vocabulary::Train(data, options)->Encode(), v->Encode());
}

TEST(VocabularyTest, KMeansFindsFloatClusters) {
  Random random(2);
  DescriptorSet data;
  data.kind = DescriptorKind::kSift;
  data.length = 128;
  for (int i = 0; i < 200; ++i) {
    const int cluster = i % 4;
    for (int k = 0; k < 128; ++k) {
      data.real.push_back(static_cast<float>((k % 4 == cluster ? 100.0 : 0.0) + random.Gaussian()));
    }
    ++data.count;
  }
  VocabularyOptions options;
  options.words = 4;
  const auto v = Vocabulary::Train(data, options);
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(v->Quantise(data).size(), 4u);
  DescriptorSet first;
  first.kind = DescriptorKind::kSift;
  first.length = 128;
  first.count = 2;
  first.real.assign(data.real.begin(), data.real.begin() + 128);
  first.real.insert(first.real.end(), data.real.begin() + 4 * 128, data.real.begin() + 5 * 128);
  EXPECT_EQ(v->Quantise(first).size(), 1u);  // rows 0 and 4 are the same cluster
}

TEST(VocabularyTest, EncodeDecodeRoundTripAndBadBytes) {
  std::vector<std::vector<uint8_t>> centres;
  VocabularyOptions options;
  options.words = 5;
  const auto v = Vocabulary::Train(ClusteredOrb(5, 10, 3, &centres), options);
  ASSERT_TRUE(v.ok());
  const std::string bytes = v->Encode();
  const auto back = Vocabulary::Decode(bytes, "v.bin");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->Encode(), bytes);
  EXPECT_EQ(back->size(), 5u);
  for (size_t cut : {size_t{0}, size_t{3}, size_t{20}, bytes.size() - 1}) {
    const auto bad = Vocabulary::Decode(bytes.substr(0, cut), "v.bin");
    ASSERT_FALSE(bad.ok());
    EXPECT_NE(bad.status().message().find("v.bin"), std::string::npos);
  }
  EXPECT_FALSE(Vocabulary::Decode(bytes + "x", "v.bin").ok());
}

TEST(VocabularyTest, TooFewDescriptorsIsAnError) {
  std::vector<std::vector<uint8_t>> centres;
  VocabularyOptions options;
  options.words = 100;
  EXPECT_FALSE(Vocabulary::Train(ClusteredOrb(2, 2, 4, &centres), options).ok());
}

TEST(VocabularyTest, FeaturesFromARealCorridorImage) {
  const std::string path = std::string(ratslam::test_paths::SharedDataDir()) +
                           "/multifloor-corridors/floor1/frame00001.jpg";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path;
  dataset::FileImageLoader loader;
  const auto image = loader.Load(path);
  ASSERT_TRUE(image.ok());
  for (DescriptorKind kind : {DescriptorKind::kOrb, DescriptorKind::kSift}) {
    FeatureOptions options;
    options.descriptor = kind;
    options.max_features = 300;
    const auto features = ExtractFeatures(*image, options);
    ASSERT_TRUE(features.ok());
    EXPECT_GT(features->count, 50u) << ToString(kind);
    EXPECT_LE(features->count, 330u);  // SIFT keeps ties at the cut
    EXPECT_EQ(features->length, kind == DescriptorKind::kOrb ? 32 : 128);
  }
  EXPECT_FALSE(ExtractFeatures(GrayImage{}, FeatureOptions{}).ok());
}

}  // namespace
}  // namespace ratslam::fabmap
