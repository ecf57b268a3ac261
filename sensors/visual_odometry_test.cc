#include "sensors/visual_odometry.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/random.h"

namespace ratslam {
namespace {

// A panorama strip; the camera sees `width` columns starting at `offset` (larger offset: the
// view has moved right across the world, i.e. the camera turned clockwise).
std::vector<uint8_t> View(const std::vector<uint8_t>& world, int offset, int width, int height) {
  std::vector<uint8_t> img(static_cast<size_t>(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) img[y * width + x] = world[(offset + x) % world.size()];
  return img;
}

TEST(VisualOdometryTest, RecoversKnownRotations) {
  Random rng(3);
  std::vector<uint8_t> world(1000);
  double smooth = 128;
  for (uint8_t& v : world) {
    smooth = std::clamp(smooth + rng.Gaussian(0, 20), 0.0, 255.0);
    v = static_cast<uint8_t>(smooth);
  }
  VisualOdometryOptions options;
  options.field_of_view_rad = 1.2;  // 120 columns: 0.01 rad per column
  VisualOdometry vo(options);
  int offset = 300;
  auto frame = [&](int o) {
    const std::vector<uint8_t> img = View(world, o, 120, 8);
    return vo.Rotation({120, 8, 120, img.data()});
  };
  EXPECT_FALSE(frame(offset).value().has_value());
  // Turning left by 4 columns: the scene moves right, the window moves left.
  offset -= 4;
  EXPECT_NEAR(*frame(offset).value(), 0.04, 1e-12);
  offset += 7;
  EXPECT_NEAR(*frame(offset).value(), -0.07, 1e-12);
  EXPECT_NEAR(*frame(offset).value(), 0.0, 1e-12);
  std::vector<uint8_t> narrow(10 * 8, 0);
  EXPECT_FALSE(vo.Rotation({10, 8, 10, narrow.data()}).ok());
}

}  // namespace
}  // namespace ratslam
