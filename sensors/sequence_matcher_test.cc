#include "sensors/sequence_matcher.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "common/random.h"

namespace ratslam::sensors {
namespace {

constexpr int kW = 64, kH = 32;

std::vector<uint8_t> Texture(uint64_t seed) {
  Random random(seed);
  std::vector<uint8_t> p(kW * kH);
  for (uint8_t& v : p) v = static_cast<uint8_t>(random.Uniform(20, 230));
  return p;
}

std::vector<uint8_t> Noisy(std::vector<uint8_t> p, double sigma, Random* random) {
  for (uint8_t& v : p) {
    v = static_cast<uint8_t>(std::clamp(std::lround(v + random->Gaussian(0, sigma)), 0L, 255L));
  }
  return p;
}

PreparedFrame Prepare(const std::vector<uint8_t>& p, const SequenceMatcherOptions& o = {}) {
  return PrepareFrame(p.data(), kW, kH, o.patch_px, o.blank_contrast);
}

// A patch of two grey levels becomes 128 -/+ 32 (one standard deviation either side); a flat
// image is blank and all 128; rows are padded with 128 to 32 bytes.
TEST(PrepareFrameTest, PatchesBecomeZeroMeanUnitSpreadBytes) {
  std::vector<uint8_t> p(8 * 2);
  for (int x = 0; x < 8; ++x) p[x] = 0, p[8 + x] = 100;  // two rows: 0s, then 100s
  const PreparedFrame f = PrepareFrame(p.data(), 8, 2, 8, 3.0);
  ASSERT_EQ(f.bytes.size(), 64u);
  EXPECT_FALSE(f.blank);
  EXPECT_EQ(f.bytes[0], 96);
  EXPECT_EQ(f.bytes[32], 160);
  EXPECT_EQ(f.bytes[8], 128);  // padding
  const std::vector<uint8_t> flat(8 * 2, 7);
  const PreparedFrame g = PrepareFrame(flat.data(), 8, 2, 8, 3.0);
  EXPECT_TRUE(g.blank);
  EXPECT_TRUE(std::all_of(g.bytes.begin(), g.bytes.end(), [](uint8_t b) { return b == 128; }));
}

// The SIMD difference equals the plain sum over the pixels, divided by their number.
TEST(FrameDifferenceTest, EqualsThePlainMeanAbsoluteDifference) {
  for (uint64_t seed = 1; seed < 20; ++seed) {
    const PreparedFrame a = Prepare(Texture(seed)), b = Prepare(Texture(seed + 100));
    double plain = 0;
    const int stride = static_cast<int>(a.bytes.size()) / kH;
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; ++x) {
        plain += std::abs(a.bytes[y * stride + x] - b.bytes[y * stride + x]);
      }
    }
    EXPECT_DOUBLE_EQ(FrameDifference(a, b), plain / (kW * kH)) << seed;
    EXPECT_EQ(FrameDifference(a, a), 0.0);
  }
}

// Perceptual aliasing: the route shows 100 places, then the same places again in another order.
std::vector<int> AliasedRoute(Random* random) {
  std::vector<int> order(100);
  std::iota(order.begin(), order.end(), 0);
  std::vector<int> shuffled = order;
  for (int i = 99; i > 0; --i) std::swap(shuffled[i], shuffled[random->NextU64() % (i + 1)]);
  order.insert(order.end(), shuffled.begin(), shuffled.end());
  return order;
}

// Perceptual aliasing: the route shows 100 places, then the same places again in another order.
// A frame of the second half looks exactly like one of the first, so a single frame cannot tell
// them apart; ten frames in order can. Every query from the tenth on is placed exactly.
TEST(SequenceMatcherTest, SequencesResolveWhatSingleFramesCannot) {
  Random random(7);
  const std::vector<int> order = AliasedRoute(&random);
  SequenceMatcherOptions options;
  SequenceMatcher matcher(options);
  for (int place : order) ASSERT_TRUE(matcher.AddReference(Prepare(Texture(place))).ok());
  int sequence_right = 0, single_right = 0, counted = 0;
  for (int j = 0; j < static_cast<int>(order.size()); ++j) {
    const auto r = matcher.AddQuery(Prepare(Noisy(Texture(order[j]), 12, &random)));
    ASSERT_TRUE(r.ok());
    if (j < options.sequence_length - 1 || j < 100) continue;  // the aliased half, full sequences
    ++counted;
    sequence_right += r->sequence.reference == j;
    single_right += r->single.reference == j;
    ASSERT_EQ(r->sequence.candidates.size(), 5u);
  }
  EXPECT_EQ(sequence_right, counted);
  // Each second-half frame has an identical twin in the first half: the two differences are
  // equal, and a tie goes to the lower index, so a single frame always answers the twin.
  EXPECT_EQ(single_right, 0);
}

// MatchAt reports the best line at any of the stored query frames: at the newest it is exactly
// the online search, and in the aliased half (every frame has an identical twin elsewhere) the
// line through the last sequence_length frames places each of them at its own reference. A blank
// query, or a frame not stored, is declined.
TEST(SequenceMatcherTest, MatchAtPlacesEveryFrameOfTheSequence) {
  Random random(11);
  const std::vector<int> order = AliasedRoute(&random);
  SequenceMatcherOptions options;
  SequenceMatcher matcher(options);
  for (int place : order) ASSERT_TRUE(matcher.AddReference(Prepare(Texture(place))).ok());
  const int length = options.sequence_length;
  for (int j = 0; j < static_cast<int>(order.size()); ++j) {
    const auto r = matcher.AddQuery(Prepare(Noisy(Texture(order[j]), 12, &random)));
    ASSERT_TRUE(r.ok());
    const SequenceMatch newest = matcher.MatchAt(0);
    EXPECT_EQ(newest.reference, r->sequence.reference);
    EXPECT_EQ(newest.confidence, r->sequence.confidence);
    ASSERT_EQ(newest.candidates.size(), r->sequence.candidates.size());
    for (size_t c = 0; c < newest.candidates.size(); ++c) {
      EXPECT_EQ(newest.candidates[c].reference, r->sequence.candidates[c].reference);
      EXPECT_EQ(newest.candidates[c].score, r->sequence.candidates[c].score);
    }
    if (j - length + 1 < 100) continue;
    for (int back = 0; back < length; ++back) {
      EXPECT_EQ(matcher.MatchAt(back).reference, j - back) << j << " back " << back;
    }
  }
  EXPECT_TRUE(matcher.MatchAt(length).declined);
  EXPECT_TRUE(matcher.MatchAt(-1).declined);
  const std::vector<uint8_t> black(kW * kH, 0);
  ASSERT_TRUE(matcher.AddQuery(Prepare(black)).ok());
  EXPECT_TRUE(matcher.MatchAt(0).declined);
  EXPECT_FALSE(matcher.MatchAt(1).declined);
  SequenceMatcherOptions online_only;
  online_only.centred = true;
  online_only.recognise_views = true;
  EXPECT_FALSE(online_only.IsValid(nullptr));
}

// A query route driven 1.2 times as fast as the reference route (every 6 reference frames in 5
// query frames) is followed within a frame once a sequence is full; a blank query is declined and
// a blank reference is never an answer.
TEST(SequenceMatcherTest, FollowsAFasterRouteAndNeverClaimsBlankFrames) {
  SequenceMatcher matcher{SequenceMatcherOptions{}};
  const std::vector<uint8_t> black(kW * kH, 0);
  for (int r = 0; r < 240; ++r) {
    ASSERT_TRUE(matcher.AddReference(Prepare(r == 120 ? black : Texture(1000 + r))).ok());
  }
  EXPECT_TRUE(matcher.reference_blank(120));
  Random random(3);
  for (int j = 0; j < 195; ++j) {
    const int truth = static_cast<int>(std::lround(1.2 * j));
    const auto r =
        matcher.AddQuery(Prepare(truth == 120 ? black : Noisy(Texture(1000 + truth), 40, &random)));
    ASSERT_TRUE(r.ok());
    if (truth == 120) {
      EXPECT_TRUE(r->sequence.declined);
      EXPECT_TRUE(r->single.declined);
      continue;
    }
    for (const PlaceCandidate& c : r->sequence.candidates) EXPECT_NE(c.reference, 120);
    for (const PlaceCandidate& c : r->single.candidates) EXPECT_NE(c.reference, 120);
    if (j >= 9) {
      EXPECT_LE(std::abs(r->sequence.reference - truth), 1) << j;
    }
  }
}

TEST(SequenceMatcherTest, FramesOfAnotherSizeAreErrors) {
  SequenceMatcher matcher{SequenceMatcherOptions{}};
  ASSERT_TRUE(matcher.AddReference(Prepare(Texture(1))).ok());
  const std::vector<uint8_t> small(32 * 16, 50);
  const PreparedFrame f = PrepareFrame(small.data(), 32, 16, 8, 3.0);
  EXPECT_NE(matcher.AddReference(f).message().find("32x16, the first was 64x32"),
            std::string::npos);
  EXPECT_FALSE(matcher.AddQuery(f).ok());
  SequenceMatcherOptions bad;
  bad.max_velocity = 0.5;
  std::string error;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_THROW(SequenceMatcher{bad}, std::invalid_argument);
}

// Area averaging: 4x2 to 2x1 is the mean of each 2x2 block; 3 to 2 columns weighs the middle
// pixel half to each side (exactly: (10 + 0.5 * 40) / 1.5 = 20 and (0.5 * 40 + 70) / 1.5 = 60).
TEST(ResizeByAreaTest, EachPixelIsTheMeanOfTheAreaItCovers) {
  const std::vector<uint8_t> blocks = {0, 10, 100, 200, 20, 30, 50, 50};
  EXPECT_EQ(ResizeByArea(blocks.data(), 4, 2, 2, 1), (std::vector<uint8_t>{15, 100}));
  const std::vector<uint8_t> three = {10, 40, 70};
  EXPECT_EQ(ResizeByArea(three.data(), 3, 1, 2, 1), (std::vector<uint8_t>{20, 60}));
  // Up-sampling copies: every output pixel lies inside one input pixel.
  EXPECT_EQ(ResizeByArea(three.data(), 3, 1, 6, 1), (std::vector<uint8_t>{10, 10, 40, 40, 70, 70}));
  // Frames of another size become the configured size before patch normalisation.
  SequenceMatcherOptions o;
  o.image_width_px = kW / 2;
  o.image_height_px = kH / 2;
  const std::vector<uint8_t> big = Texture(5);
  const PreparedFrame f = PrepareFrame(big.data(), kW, kH, o);
  EXPECT_EQ(f.width, kW / 2);
  EXPECT_EQ(f.height, kH / 2);
  o.image_height_px = 0;
  EXPECT_FALSE(o.IsValid(nullptr));  // both sizes or neither
}

// Recognition while mapping: one route driven twice, each frame queried against the frames
// before it and then added. `searchable` keeps the newest 30 frames out of the answers, and
// every frame of the second lap (noisier) is placed on its first-lap twin, with a margin, once
// its sequence is full.
TEST(SequenceMatcherTest, GrowingReferencesRecogniseTheSecondLap) {
  SequenceMatcherOptions options;
  SequenceMatcher matcher(options);
  Random random(11);
  const int lap = 120;
  int placed = 0;
  for (int j = 0; j < 2 * lap; ++j) {
    const PreparedFrame f = Prepare(Noisy(Texture(500 + j % lap), j < lap ? 5 : 30, &random));
    const int searchable = std::max(0, static_cast<int>(matcher.references()) - 30);
    const auto r = matcher.AddQuery(f, 1, searchable);
    ASSERT_TRUE(r.ok());
    if (searchable == 0) {
      EXPECT_TRUE(r->sequence.declined) << j;
    } else {
      EXPECT_LT(r->sequence.reference, searchable) << j;
    }
    if (j >= lap + options.sequence_length - 1) {
      EXPECT_EQ(r->sequence.reference, j - lap) << j;
      EXPECT_GE(r->sequence.confidence, 0.3) << j;
      ++placed;
    }
    ASSERT_TRUE(matcher.AddReference(f).ok());
  }
  EXPECT_EQ(placed, lap - options.sequence_length + 1);
}

// Saved state resumes to the same answers; a state with a row longer than the references, or a
// reference of another size, is refused and the matcher keeps what it had.
TEST(SequenceMatcherTest, StateRoundTripsAndBadStateIsRefused) {
  SequenceMatcherOptions options;
  SequenceMatcher a(options);
  Random random(2);
  for (int j = 0; j < 60; ++j) {
    const PreparedFrame f = Prepare(Texture(900 + j % 30));
    ASSERT_TRUE(a.AddQuery(f, 1).ok());
    ASSERT_TRUE(a.AddReference(f).ok());
  }
  SequenceMatcher b(options);
  ASSERT_TRUE(b.SetState(a.state()).ok());
  for (int j = 0; j < 10; ++j) {
    const PreparedFrame f = Prepare(Noisy(Texture(900 + j), 20, &random));
    const auto ra = a.AddQuery(f, 3), rb = b.AddQuery(f, 3);
    ASSERT_TRUE(ra.ok() && rb.ok());
    EXPECT_EQ(ra->sequence.reference, rb->sequence.reference);
    EXPECT_EQ(ra->sequence.confidence, rb->sequence.confidence);
  }
  SequenceMatcher::State bad = a.state();
  bad.rows.back().enhanced.push_back(0.0f);
  bad.rows.back().enhanced.resize(bad.references.size() + 1);
  EXPECT_FALSE(b.SetState(bad).ok());
  bad = a.state();
  bad.references[3].bytes.pop_back();
  EXPECT_FALSE(b.SetState(bad).ok());
  bad = a.state();
  bad.rows.front().neutral = std::nanf("");
  EXPECT_FALSE(b.SetState(bad).ok());
  EXPECT_EQ(b.references(), a.references());
}

// Rows of differences given directly (references without pixels): a route travelled at 1.2
// reference frames per query frame, every row a noisy dip at the true place over a flat floor
// with a decoy as deep as the dip at a random place. Single frames are fooled by the decoys
// about half the time; sequences, which the decoys do not line up for, are within a frame once
// full. A row of the wrong length, a NaN and a negative difference are errors.
TEST(SequenceMatcherTest, RowsOfDifferencesFromElsewhere) {
  SequenceMatcher matcher{SequenceMatcherOptions{}};
  const int n = 300;
  for (int r = 0; r < n; ++r) ASSERT_TRUE(matcher.AddReference(PreparedFrame{}).ok());
  Random random(8);
  int single_right = 0, queries = 0;
  for (int j = 0; j < 200; ++j) {
    const int truth = static_cast<int>(std::lround(10 + 1.2 * j));
    std::vector<float> row(n);
    for (int r = 0; r < n; ++r) row[r] = static_cast<float>(1.0 + random.Uniform(0, 0.1));
    row[truth] = static_cast<float>(random.Uniform(0.3, 0.6));
    if (random.Uniform(0, 1) < 0.5) row[static_cast<int>(random.Uniform(0, n))] = 0.2f;
    const auto r = matcher.AddQueryDifferences(row, false);
    ASSERT_TRUE(r.ok()) << r.status().message();
    ++queries;
    single_right += r->single.reference == truth;
    if (j >= 9) {
      EXPECT_LE(std::abs(r->sequence.reference - truth), 1) << j;
    }
  }
  EXPECT_LT(single_right, queries * 3 / 4);
  EXPECT_FALSE(matcher.AddQueryDifferences(std::vector<float>(n - 1, 1.0f), false).ok());
  std::vector<float> bad(n, 1.0f);
  bad[7] = std::nanf("");
  EXPECT_NE(matcher.AddQueryDifferences(bad, false).status().message().find("reference 7"),
            std::string::npos);
  bad[7] = -0.5f;
  EXPECT_FALSE(matcher.AddQueryDifferences(bad, false).ok());
}

}  // namespace
}  // namespace ratslam::sensors
