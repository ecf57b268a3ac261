#include "sensors/classic_camera_matcher.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

namespace ratslam::sensors {
namespace {

struct Image {
  int width, height;
  std::vector<uint8_t> pixels;
  GrayImageView view() const { return {width, height, width, pixels.data()}; }
};

Image RandomImage(int width, int height, uint32_t seed) {
  std::mt19937 rng(seed);
  Image image{width, height, std::vector<uint8_t>(static_cast<size_t>(width) * height)};
  for (uint8_t& p : image.pixels) p = static_cast<uint8_t>(rng() % 256);
  return image;
}

// Rotates the columns of an image: output column x shows input column x - shift.
Image RollColumns(const Image& in, int shift) {
  Image out = in;
  for (int y = 0; y < in.height; ++y)
    for (int x = 0; x < in.width; ++x)
      out.pixels[y * in.width + x] =
          in.pixels[y * in.width + ((x - shift) % in.width + in.width) % in.width];
  return out;
}

TEST(ClassicCameraOptionsTest, DefaultsAreValid) {
  std::string error;
  EXPECT_TRUE(ClassicCameraOptions().IsValid(&error)) << error;
}

TEST(ClassicCameraMatcherTest, SameImageMatchesDifferentImageIsNew) {
  ClassicCameraMatcher matcher({});
  const Image a = RandomImage(120, 40, 1), b = RandomImage(120, 40, 2);
  auto first = matcher.Observe(a.view(), 0.0);
  ASSERT_TRUE(first.ok());
  EXPECT_TRUE(first->is_new);
  EXPECT_EQ(first->template_id, 0u);
  auto second = matcher.Observe(b.view(), 0.1);
  ASSERT_TRUE(second.ok());
  EXPECT_TRUE(second->is_new);
  EXPECT_EQ(second->template_id, 1u);
  auto again = matcher.Observe(a.view(), 0.2);
  ASSERT_TRUE(again.ok());
  EXPECT_FALSE(again->is_new);
  EXPECT_EQ(again->template_id, 0u);
}

// The SIMD comparison equals the definition: mean |q - t| over the overlapping columns.
TEST(ClassicCameraMatcherTest, ComparisonEqualsReferenceMeanAbsoluteDifference) {
  ClassicCameraOptions options;
  options.template_width_px = 37;  // not a multiple of 16: exercises padding and masks
  options.template_height_px = 5;
  options.shift_px = 4;
  options.shift_step_px = 2;
  ClassicCameraMatcher matcher(options);
  const Image a = RandomImage(37, 5, 3), b = RandomImage(37, 5, 4);
  auto ta = matcher.MakeTemplate(a.view()).value();
  auto tb = matcher.MakeTemplate(b.view()).value();
  matcher.Add(ta);
  const TemplateComparison got = matcher.Compare(tb);
  double best = 1e300;
  int best_shift = 0;
  for (int s = -4; s <= 4; s += 2) {
    double sum = 0.0;
    int n = 0;
    for (int y = 0; y < 5; ++y)
      for (int u = 0; u < 37; ++u) {
        if (u + s < 0 || u + s >= 37) continue;
        sum += std::abs(int(b.pixels[y * 37 + u + s]) - int(a.pixels[y * 37 + u])) / 255.0;
        ++n;
      }
    if (sum / n < best) {
      best = sum / n;
      best_shift = s;
    }
  }
  EXPECT_NEAR(got.mean_difference, best, 1e-12);
  EXPECT_EQ(got.shift_px, best_shift);
}

TEST(ClassicCameraMatcherTest, ShiftedViewMatchesWithTheShift) {
  ClassicCameraOptions options;
  options.template_width_px = 60;
  options.template_height_px = 10;
  ClassicCameraMatcher matcher(options);
  const Image a = RandomImage(60, 10, 5);
  matcher.Add(matcher.MakeTemplate(a.view()).value());
  const TemplateComparison c =
      matcher.Compare(matcher.MakeTemplate(RollColumns(a, 3).view()).value());
  EXPECT_EQ(c.shift_px, 3);
  EXPECT_EQ(c.mean_difference, 0.0);
}

TEST(ClassicCameraMatcherTest, PanoramicMatchGivesHeadingChange) {
  ClassicCameraOptions options;
  options.template_width_px = 36;
  options.template_height_px = 4;
  options.shift_px = 9;
  options.panoramic = true;
  ClassicCameraMatcher matcher(options);
  const Image a = RandomImage(36, 4, 6);
  ASSERT_TRUE(matcher.Observe(a.view(), 0.0)->is_new);
  auto turned = matcher.Observe(RollColumns(a, -9).view(), 1.0);  // wraps around the edge
  ASSERT_TRUE(turned.ok());
  EXPECT_FALSE(turned->is_new);
  EXPECT_NEAR(turned->heading_change_rad, -std::numbers::pi / 2, 1e-12);
}

// A panorama searches the whole ring (as OpenRatSLAM does), not only +-shift_px: a place seen
// facing the other way matches with a heading change of half a turn.
TEST(ClassicCameraMatcherTest, PanoramicMatchSearchesTheWholeRing) {
  ClassicCameraOptions options;
  options.template_width_px = 36;
  options.template_height_px = 4;
  options.shift_px = 3;  // not used by a panorama
  options.shift_step_px = 2;
  options.panoramic = true;
  ClassicCameraMatcher matcher(options);
  const Image a = RandomImage(36, 4, 8);
  ASSERT_TRUE(matcher.Observe(a.view(), 0.0)->is_new);
  auto behind = matcher.Observe(RollColumns(a, 18).view(), 1.0);
  ASSERT_TRUE(behind.ok());
  EXPECT_FALSE(behind->is_new);
  EXPECT_NEAR(std::abs(behind->heading_change_rad), std::numbers::pi, 1e-12);
  // An odd roll between the steps' offsets is not an exact match any more.
  const TemplateComparison odd =
      matcher.Compare(matcher.MakeTemplate(RollColumns(a, 5).view()).value());
  EXPECT_GT(odd.mean_difference, 0.0);
  EXPECT_EQ(matcher.Compare(matcher.MakeTemplate(RollColumns(a, 6).view()).value()).mean_difference,
            0.0);
}

TEST(ClassicCameraMatcherTest, BlockMeanAndCrop) {
  ClassicCameraOptions options;
  options.crop_left_px = 2;
  options.crop_right_px = 6;
  options.template_width_px = 2;
  options.template_height_px = 1;
  options.shift_px = 0;
  ClassicCameraMatcher matcher(options);
  // Row values: columns 2,3 = 0 and 255 -> mean 0.5; columns 4,5 = 255 -> 1.0.
  Image image{8, 1, {9, 9, 0, 255, 255, 255, 9, 9}};
  auto t = matcher.MakeTemplate(image.view()).value();
  EXPECT_EQ(t[0], 128);  // round(0.5 * 255)
  EXPECT_EQ(t[1], 255);
}

TEST(ClassicCameraMatcherTest, ImageSmallerThanCropIsAnError) {
  ClassicCameraOptions options;
  options.crop_right_px = 200;
  ClassicCameraMatcher matcher(options);
  const Image a = RandomImage(100, 40, 7);
  auto result = matcher.Observe(a.view(), 0.0);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.status().message().find(
                "[camera] crop_right_px = 200 lies outside the 100x40 px image"),
            std::string::npos)
      << result.status().message();
  // A left edge far outside is blamed on its key too (it once read as a negative crop width).
  ClassicCameraOptions far;
  far.crop_left_px = 2000000000;
  ClassicCameraMatcher far_matcher(far);
  auto far_result = far_matcher.Observe(a.view(), 0.0);
  ASSERT_FALSE(far_result.ok());
  EXPECT_NE(far_result.status().message().find("[camera] crop_left_px = 2000000000 lies outside"),
            std::string::npos)
      << far_result.status().message();
}

TEST(ClassicCameraMatcherTest, PatchNormalisationRemovesBrightnessChange) {
  ClassicCameraOptions options;
  options.patch_normalisation_radius_px = 2;
  options.template_width_px = 20;
  options.template_height_px = 8;
  options.shift_px = 2;
  ClassicCameraMatcher matcher(options);
  Image a = RandomImage(20, 8, 8);
  for (uint8_t& p : a.pixels) p = static_cast<uint8_t>(p / 2 + 20);
  Image darker = a;
  for (uint8_t& p : darker.pixels) p = static_cast<uint8_t>(p / 2);  // halve all intensities
  matcher.Add(matcher.MakeTemplate(a.view()).value());
  const TemplateComparison c = matcher.Compare(matcher.MakeTemplate(darker.view()).value());
  EXPECT_LT(c.mean_difference, 0.02);
}

}  // namespace
}  // namespace ratslam::sensors

namespace ratslam::sensors {
namespace {

// Views along a route: a smooth panorama seen from nearby positions (shifted, brightened,
// noisy), so that many stored templates are near the query and the bound must decide close
// calls. Returns row-major images of width x height.
std::vector<Image> RouteViews(int width, int height, int count, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 6.0);
  std::vector<double> world(4 * width);
  for (size_t i = 0; i < world.size(); ++i) {
    world[i] = 128 + 60 * std::sin(i * 0.07) + 40 * std::sin(i * 0.31 + 1.0);
  }
  std::vector<Image> views;
  for (int v = 0; v < count; ++v) {
    Image image{width, height, std::vector<uint8_t>(static_cast<size_t>(width) * height)};
    const int offset = (v * 7) % (3 * width);
    const double gain = 0.9 + 0.2 * (v % 5) / 4.0;
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const double value = world[offset + x] * gain * (0.8 + 0.4 * y / height) + noise(rng);
        image.pixels[y * width + x] = static_cast<uint8_t>(std::clamp(value, 0.0, 255.0));
      }
    views.push_back(image);
  }
  return views;
}

// The full scan as the reference: the first template of the smallest difference (Differences
// visits every template without the bound).
// `thorough`: every cutoff and hint below; otherwise a tie at the cutoff and just below it.
void ExpectBoundedScanEqualsFullScan(ClassicCameraOptions options, const std::vector<Image>& stored,
                                     const std::vector<Image>& queries, bool portable,
                                     bool thorough = true) {
  ClassicCameraMatcher matcher(options);
  matcher.set_force_portable(portable);
  for (const Image& s : stored) matcher.Add(matcher.MakeTemplate(s.view()).value());
  for (const Image& q : queries) {
    const std::vector<uint8_t> query = matcher.MakeTemplate(q.view()).value();
    const std::vector<double> all = matcher.Differences(query);
    const auto first_min = std::min_element(all.begin(), all.end());  // first of the smallest
    const int64_t count = matcher.size();
    // Without a hint, and with hints that are the answer, elsewhere, or out of range.
    for (int64_t hint :
         {int64_t{-1}, int64_t{first_min - all.begin()}, int64_t{0}, count - 1, count / 2, count}) {
      const TemplateComparison got = matcher.Compare(query, hint);
      ASSERT_EQ(got.template_id, first_min - all.begin()) << "hint " << hint;
      ASSERT_EQ(got.mean_difference, *first_min) << "hint " << hint;  // bit for bit
    }
    // With a cutoff: the same answer when it is within (a tie at the cutoff counts), none when
    // not. The cutoffs straddle the answer and a range of other templates' differences.
    std::vector<double> sorted = all;
    std::sort(sorted.begin(), sorted.end());
    std::vector<double> cutoffs = {*first_min, std::nextafter(*first_min, 0.0)};
    std::vector<int64_t> hints = {-1};
    if (thorough) {
      cutoffs.insert(cutoffs.end(), {*first_min * 2.0, sorted[sorted.size() / 10],
                                     sorted[sorted.size() / 2], 0.0, 1.0});
      hints.insert(hints.end(), {first_min - all.begin(), count / 2});
    }
    for (double cutoff : cutoffs) {
      for (int64_t hint : hints) {
        const TemplateComparison got = matcher.Compare(query, hint, cutoff);
        if (*first_min <= cutoff) {
          ASSERT_EQ(got.template_id, first_min - all.begin()) << "cutoff " << cutoff;
          ASSERT_EQ(got.mean_difference, *first_min) << "cutoff " << cutoff;
        } else {
          ASSERT_EQ(got.template_id, -1) << "cutoff " << cutoff << " hint " << hint;
        }
      }
    }
  }
}

TEST(ClassicCameraBoundTest, BoundedScanEqualsFullScanOnRouteViews) {
  const std::vector<Image> views = RouteViews(120, 40, 600, 5);
  const std::vector<Image> stored(views.begin(), views.begin() + 500);
  const std::vector<Image> queries(views.begin() + 500, views.end());
  for (bool portable : {false, true}) {
    for (bool panoramic : {false, true}) {
      ClassicCameraOptions options;
      options.panoramic = panoramic;
      ExpectBoundedScanEqualsFullScan(options, stored, queries, portable);
      options.shift_step_px = 2;
      options.template_width_px = 37;  // padding and masks
      options.template_height_px = 7;
      options.global_normalisation_mean = 0.5;
      ExpectBoundedScanEqualsFullScan(options, stored, queries, portable);
    }
  }
}

TEST(ClassicCameraBoundTest, BoundedScanEqualsFullScanOnRandomTemplatesWithTies) {
  std::vector<Image> stored;
  for (uint32_t i = 0; i < 300; ++i) stored.push_back(RandomImage(120, 40, 100 + i % 150));
  std::vector<Image> queries;  // half of them equal to stored images: exact ties at 0
  for (uint32_t i = 0; i < 40; ++i)
    queries.push_back(RandomImage(120, 40, i % 2 ? 100 + i : 900 + i));
  // Stored images made uniformly brighter: their difference equals the column-sum total bound
  // exactly, so a cutoff at the answer leaves the index no slack.
  for (uint32_t i = 0; i < 10; ++i) {
    Image lifted = stored[i * 7];
    for (uint8_t& p : lifted.pixels) p = static_cast<uint8_t>(p * 200 / 255 + 5 + i);
    queries.push_back(lifted);
    for (uint8_t& p : lifted.pixels) p = static_cast<uint8_t>(p - 2 * (5 + i));  // and darker
    queries.push_back(lifted);
  }
  for (bool portable : {false, true}) {
    ExpectBoundedScanEqualsFullScan({}, stored, queries, portable);
  }
}

// Templates of over 8.4 million pixels: the bound no longer fits 32 bits and takes its 64-bit path.
TEST(ClassicCameraBoundTest, BoundedScanEqualsFullScanOnHugeTemplates) {
  ClassicCameraOptions options;
  options.template_width_px = 4096;
  options.template_height_px = 2060;  // 4096 * 2060 * 255 > 2^31
  options.shift_px = 1;
  std::vector<Image> stored;
  for (uint32_t i = 0; i < 2; ++i) stored.push_back(RandomImage(4096, 2060, 40 + i));
  ExpectBoundedScanEqualsFullScan(options, stored, {stored[1], RandomImage(4096, 2060, 7)}, false,
                                  /*thorough=*/false);
}

// Cutoffs that admit nothing (zero with no exact copy, negative, NaN) give no template, and do
// not upset the index.
TEST(ClassicCameraBoundTest, CutoffThatAdmitsNothingGivesNoTemplate) {
  ClassicCameraMatcher matcher({});
  for (uint32_t i = 0; i < 50; ++i)
    matcher.Add(matcher.MakeTemplate(RandomImage(120, 40, i).view()).value());
  const std::vector<uint8_t> query = matcher.MakeTemplate(RandomImage(120, 40, 99).view()).value();
  for (double cutoff : {0.0, -1.0, -1e300, std::nan("")}) {
    EXPECT_EQ(matcher.Compare(query, -1, cutoff).template_id, -1) << cutoff;
    EXPECT_EQ(matcher.Compare(query, 3, cutoff).template_id, -1) << cutoff;
  }
  EXPECT_GE(matcher.Compare(query, -1, 1.0).template_id, 0);
}

// A matcher reloaded from its state answers as the one that stored the templates (the total
// index is rebuilt, not saved).
TEST(ClassicCameraBoundTest, RestoredMatcherAnswersAsTheOriginal) {
  const std::vector<Image> views = RouteViews(120, 40, 300, 8);
  ClassicCameraOptions options;
  options.match_threshold = 0.02;
  ClassicCameraMatcher original(options);
  for (int i = 0; i < 250; ++i) ASSERT_TRUE(original.Observe(views[i].view(), i).ok());
  ClassicCameraMatcher restored(options);
  ASSERT_TRUE(restored.SetState(original.state()).ok());
  ASSERT_TRUE(restored.SetState(original.state()).ok());  // twice: no stale index entries
  for (int i = 250; i < 300; ++i) {
    const std::vector<uint8_t> query = original.MakeTemplate(views[i].view()).value();
    for (double cutoff : {0.005, 0.02, 0.1}) {
      const TemplateComparison a = original.Compare(query, -1, cutoff);
      const TemplateComparison b = restored.Compare(query, -1, cutoff);
      ASSERT_EQ(a.template_id, b.template_id);
      ASSERT_EQ(a.mean_difference, b.mean_difference);
      ASSERT_EQ(a.shift_px, b.shift_px);
    }
  }
}

// A tight cutoff visits only templates whose column-sum total is near the query's: on views of
// many brightnesses, far fewer than all, and fewer than the scan without a cutoff compares.
TEST(ClassicCameraBoundTest, CutoffVisitsFewTemplatesOfOtherBrightness) {
  std::vector<Image> views;
  for (int i = 0; i < 400; ++i) {
    Image image = RandomImage(120, 40, 300 + i);
    const int lift = (i * 37) % 200 - 100;  // brightness offsets spread over -100..99
    for (uint8_t& p : image.pixels)
      p = static_cast<uint8_t>(std::clamp(p / 2 + 64 + lift / 2, 0, 255));
    views.push_back(image);
  }
  ClassicCameraMatcher matcher({});
  for (int i = 0; i < 300; ++i) matcher.Add(matcher.MakeTemplate(views[i].view()).value());
  for (int i = 300; i < 400; ++i) {
    matcher.Compare(matcher.MakeTemplate(views[i].view()).value(), -1, 0.01);
  }
  // The totals of 300 templates spread over ~100 grey levels; a 0.01 cutoff is 2.55 levels
  // either side (a few per cent), so well under a tenth should be visited.
  EXPECT_LT(matcher.bounds_checked(), 100u * 300u / 10) << matcher.bounds_checked();
}

TEST(ClassicCameraBoundTest, BoundSkipsMostTemplatesOnRouteViews) {
  const std::vector<Image> views = RouteViews(120, 40, 600, 6);
  ClassicCameraMatcher matcher({});
  for (int i = 0; i < 500; ++i) matcher.Add(matcher.MakeTemplate(views[i].view()).value());
  for (int i = 500; i < 600; ++i) matcher.Compare(matcher.MakeTemplate(views[i].view()).value());
  // 100 queries x 500 templates: the bound must leave well under half for the full comparison.
  EXPECT_LT(matcher.full_comparisons(), 100u * 500u / 2) << matcher.full_comparisons();
}

}  // namespace
}  // namespace ratslam::sensors
