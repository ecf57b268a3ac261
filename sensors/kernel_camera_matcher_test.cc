#include "sensors/kernel_camera_matcher.h"

#include <gtest/gtest.h>

#include <cmath>

namespace ratslam::sensors {
namespace {

TEST(KernelCameraOptionsTest, DefaultsAreValid) {
  std::string error;
  EXPECT_TRUE(KernelCameraOptions().IsValid(&error)) << error;
}

std::vector<uint8_t> Gradient(int w, int h, int offset) {
  std::vector<uint8_t> p(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      p[y * w + x] = static_cast<uint8_t>((x * 7 + y * 11 + offset) % 200);
  return p;
}

TEST(KernelCameraMatcherTest, Equation7OnKnownDifference) {
  KernelCameraOptions options;
  options.subtract_mean = false;
  KernelCameraMatcher m(options);
  // Two templates differing by 0.05 in each of the 108 pixels:
  // c = exp(-108 * 0.05^2 / (2 * 2^2)) = exp(-0.03375).
  std::vector<float> a(108, 0.5f), b(108, 0.55f);
  EXPECT_NEAR(m.Similarity(a, b), std::exp(-108 * 0.05 * 0.05 / 8.0), 1e-6);
  EXPECT_DOUBLE_EQ(m.Similarity(a, a), 1.0);
}

TEST(KernelCameraMatcherTest, BlockMeansAndMeanSubtraction) {
  KernelCameraMatcher m({});
  // A 24x18 image of constant 102: every block mean is 0.4; minus the mean: all zero.
  std::vector<uint8_t> flat(24 * 18, 102);
  auto t = m.MakeTemplate({24, 18, 24, flat.data()});
  ASSERT_TRUE(t.ok());
  ASSERT_EQ(t->size(), 108u);
  for (float v : *t) EXPECT_NEAR(v, 0.0f, 1e-6);
  // A uniformly brighter image is the same template when the mean is subtracted.
  std::vector<uint8_t> img = Gradient(48, 36, 0), brighter = img;
  for (uint8_t& p : brighter) p = static_cast<uint8_t>(p + 30);
  EXPECT_NEAR(m.Similarity(*m.MakeTemplate({48, 36, 48, img.data()}),
                           *m.MakeTemplate({48, 36, 48, brighter.data()})),
              1.0, 1e-9);
  EXPECT_FALSE(m.MakeTemplate({8, 8, 8, flat.data()}).ok());
}

TEST(KernelCameraMatcherTest, BestPicksTheNearestTemplate) {
  KernelCameraMatcher m({});
  for (int k = 0; k < 5; ++k) {
    std::vector<uint8_t> img = Gradient(48, 36, k * 37);
    m.Add(*m.MakeTemplate({48, 36, 48, img.data()}));
  }
  std::vector<uint8_t> q = Gradient(48, 36, 3 * 37);
  const KernelCameraMatch best = m.Best(*m.MakeTemplate({48, 36, 48, q.data()}));
  EXPECT_EQ(best.id, 3);
  EXPECT_DOUBLE_EQ(best.similarity, 1.0);
}

}  // namespace
}  // namespace ratslam::sensors
