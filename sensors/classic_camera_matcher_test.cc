#include "sensors/classic_camera_matcher.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace ratslam {
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
  EXPECT_NE(result.status().message().find("smaller than the crop"), std::string::npos);
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
}  // namespace ratslam
