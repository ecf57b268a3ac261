#include "fusion/fabmap/wifi_words.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace ratslam::fabmap {
namespace {

WifiVocabulary MakeVocabulary(int bins, WifiEncoding encoding) {
  WifiWordOptions options;
  options.bins = bins;
  options.encoding = encoding;
  WifiVocabulary v(options);
  v.AddAccessPoints({{"aa", -50}, {"bb", -60}});
  v.AddAccessPoints({{"bb", -70}, {"cc", -80}});
  return v;
}

TEST(WifiWordsTest, BinsOverTheUsableRange) {
  // b = 5 over ]-90, 0]: bins of 18 dB, ]-90,-72], ]-72,-54], ]-54,-36], ]-36,-18], ]-18,0].
  const WifiVocabulary v = MakeVocabulary(5, WifiEncoding::kExclusive);
  EXPECT_EQ(v.Bin(-90.0), -1);  // at the floor: not usable
  EXPECT_EQ(v.Bin(-95.0), -1);
  EXPECT_EQ(v.Bin(NAN), -1);
  EXPECT_EQ(v.Bin(-89.9), 0);
  EXPECT_EQ(v.Bin(-72.0), 0);
  EXPECT_EQ(v.Bin(-71.9), 1);
  EXPECT_EQ(v.Bin(-40.0), 2);
  EXPECT_EQ(v.Bin(0.0), 4);
  EXPECT_EQ(v.Bin(12.0), 4);  // above the range: top bin
}

TEST(WifiWordsTest, ExclusiveAndIncrementalWorkedExample) {
  // APs in order of first sighting: aa=0, bb=1, cc=2; 5 words each.
  const WifiVocabulary exclusive = MakeVocabulary(5, WifiEncoding::kExclusive);
  EXPECT_EQ(exclusive.access_points(), 3u);
  EXPECT_EQ(exclusive.size(), 15u);
  const std::vector<WifiReading> scan = {{"cc", -40}, {"aa", -80}, {"zz", -30}, {"bb", -95}};
  // cc at -40 dBm: bin 2 -> word 2*5+2; aa at -80: bin 0 -> word 0; zz unknown; bb too weak.
  EXPECT_EQ(exclusive.Encode(scan), (Observation{0, 12}));
  const WifiVocabulary incremental = MakeVocabulary(5, WifiEncoding::kIncremental);
  EXPECT_EQ(incremental.Encode(scan), (Observation{0, 10, 11, 12}));
  // b = 1: presence only, both encodings alike.
  const WifiVocabulary presence = MakeVocabulary(1, WifiEncoding::kIncremental);
  EXPECT_EQ(presence.Encode(scan), (Observation{0, 2}));
  // A repeated AP is averaged: -50 and -30 -> -40, bin 2.
  EXPECT_EQ(exclusive.Encode({{"aa", -50}, {"aa", -30}}), (Observation{2}));
}

TEST(WifiWordsTest, VirtualSamplesHaveTheConfiguredStatistics) {
  WifiWordOptions options;
  options.bins = 4;
  WifiVocabulary v(options);
  std::vector<WifiReading> aps;
  for (int i = 0; i < 60; ++i) aps.push_back({"ap" + std::to_string(i), -50});
  v.AddAccessPoints(aps);
  VirtualSampleOptions sample_options;
  sample_options.samples = 4000;
  sample_options.p_known = 0.5;
  const auto samples = VirtualWifiSamples(v, 20.0, 4.0, sample_options);
  ASSERT_EQ(samples.size(), 4000u);
  // Exclusive: one word per known AP; known APs ~ 0.5 * N(20, 4): mean 10, variance
  // E[Var] + Var[E] = 20*0.25 + 0.25*16 = 9.
  double sum = 0.0, sum_sq = 0.0;
  std::vector<int> bin_count(4, 0);
  for (const auto& s : samples) {
    sum += s.size();
    sum_sq += static_cast<double>(s.size()) * s.size();
    for (WordId w : s) ++bin_count[w % 4];
  }
  const double mean = sum / samples.size();
  const double variance = sum_sq / samples.size() - mean * mean;
  EXPECT_NEAR(mean, 10.0, 0.2);
  EXPECT_NEAR(variance, 9.0, 0.8);
  // RSSI uniform over the range: every bin about a quarter of the words.
  for (int count : bin_count) EXPECT_NEAR(count / sum, 0.25, 0.02);
  // Seeded: the same seed gives the same samples, another seed others.
  EXPECT_EQ(VirtualWifiSamples(v, 20.0, 4.0, sample_options), samples);
  sample_options.seed = 2;
  EXPECT_NE(VirtualWifiSamples(v, 20.0, 4.0, sample_options), samples);
}

TEST(WifiWordsTest, CountStatisticsAndSpacing) {
  double mean = 0.0, sigma = 0.0;
  CountStatistics({{{"a", -50}, {"b", -50}}, {{"a", -50}, {"a", -60}, {"c", -40}, {"d", -70}}},
                  &mean, &sigma);
  EXPECT_DOUBLE_EQ(mean, 2.5);  // 2 and 3 distinct APs
  EXPECT_DOUBLE_EQ(sigma, 0.5);
  const auto kept = SpacedIndices({0, 1, 2, 5, 6, 9}, {0, 10, 20, 25, 40, 41}, 2.0, 10.0);
  EXPECT_EQ(kept, (std::vector<size_t>{0, 2, 4}));
  // A second session restarts travel and time.
  EXPECT_EQ(SpacedIndices({0, 3, 0, 3}, {0, 20, 0, 20}, 2.0, 10.0),
            (std::vector<size_t>{0, 1, 2, 3}));
}

// Fingerprint data sets (UJIIndoorLoc rows) record no travel: spacing by travel must not
// collapse them to their first scan (it did: 1 of 7,974 map rows learnt the tree).
TEST(WifiWordsTest, SpacingWithoutTravelUsesTimeOnly) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> none(5, nan);
  EXPECT_EQ(SpacedIndices(none, {0, 0, 1, 1, 2}, 1.0, 0.0), (std::vector<size_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(SpacedIndices(none, {0, 4, 10, 12, 25}, 1.0, 10.0), (std::vector<size_t>{0, 2, 4}));
  // Travel known for some rows only: the distance applies between rows that both have it.
  EXPECT_EQ(SpacedIndices({0, 0.5, nan, 0.7, 3}, {0, 1, 2, 3, 4}, 1.0, 0.0),
            (std::vector<size_t>{0, 2, 3, 4}));
}

TEST(WifiWordsTest, OptionsAreChecked) {
  std::string error;
  EXPECT_TRUE(WifiWordOptions{}.IsValid(&error));
  WifiWordOptions bad;
  bad.bins = 0;
  EXPECT_FALSE(bad.IsValid(&error));
  bad = {};
  bad.min_rssi_dbm = 0.0;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_TRUE(VirtualSampleOptions{}.IsValid(&error));
  EXPECT_FALSE(WifiEncodingFromString("exclusiv").ok());
  EXPECT_EQ(WifiEncodingFromString("incremental").value(), WifiEncoding::kIncremental);
}

}  // namespace
}  // namespace ratslam::fabmap
