#include "sensors/visual_odometry.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/random.h"

namespace ratslam::sensors {
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

// OpenRatSLAM's model on images built so that every answer is known by hand: the top rows
// (rotation region) show a textured strip shifted by whole pixels, the bottom rows (speed region)
// a flat grey whose change gives the mean profile difference.
class OpenRatslamVisualOdometryTest : public ::testing::Test {
 protected:
  static constexpr int kWidth = 100, kHeight = 12;
  void SetUp() override {
    options_.model = "openratslam";
    options_.max_shift_px = 39;
    options_.field_of_view_rad = 50 * M_PI / 180;  // OpenRatSLAM's default camera_fov_deg
    options_.camera_hz = 10;
    options_.translation_scaling = 100;
    options_.max_speed_m_per_s = 20;
    options_.rotation_bottom_px = 6;
    options_.translation_top_px = 6;
    Random rng(5);
    world_.resize(400);
    for (uint8_t& v : world_) v = static_cast<uint8_t>(rng.Uniform(0, 255));
  }
  // The strip from world column `offset`, and a flat `grey` below.
  std::vector<uint8_t> Frame(int offset, uint8_t grey) const {
    std::vector<uint8_t> img(static_cast<size_t>(kWidth) * kHeight, grey);
    for (int y = 0; y < 6; ++y) {
      for (int x = 0; x < kWidth; ++x)
        img[static_cast<size_t>(y * kWidth + x)] = world_[offset + x];
    }
    return img;
  }
  StatusOr<std::optional<VisualVelocities>> Step(OpenRatslamVisualOdometry& vo,
                                                 const std::vector<uint8_t>& img) {
    return vo.Step({kWidth, kHeight, kWidth, img.data()});
  }
  VisualOdometryOptions options_;
  std::vector<uint8_t> world_;
};

TEST_F(OpenRatslamVisualOdometryTest, ShiftGivesTurnRateAndGreyChangeGivesSpeed) {
  OpenRatslamVisualOdometry vo(options_);
  auto first = Step(vo, Frame(200, 100));
  ASSERT_TRUE(first.ok()) << first.status().message();
  EXPECT_FALSE(first->has_value());  // the first frame only starts the profiles
  // The window moves 3 columns left across the world: content moves 3 px right, +3 px.
  auto turned = Step(vo, Frame(197, 110));
  ASSERT_TRUE(turned.ok() && turned->has_value());
  const double per_px = (50 * M_PI / 180) / kWidth * 10;  // fov / width * camera_hz
  EXPECT_NEAR(turned->value().turn_rate_rad_per_s, 3 * per_px, 1e-12);
  EXPECT_NEAR(turned->value().forward_m_per_s, 100 * 10 / 255.0, 1e-12);
  // 7 columns the other way, and a grey jump whose speed is clipped at max_speed_m_per_s.
  auto back = Step(vo, Frame(204, 200));
  ASSERT_TRUE(back.ok() && back->has_value());
  EXPECT_NEAR(back->value().turn_rate_rad_per_s, -7 * per_px, 1e-12);
  EXPECT_EQ(back->value().forward_m_per_s, 20.0);
  // Nothing moves and nothing changes: zero, and shift 0 wins every tie (it is tried first).
  auto still = Step(vo, Frame(204, 200));
  ASSERT_TRUE(still.ok() && still->has_value());
  EXPECT_EQ(still->value().turn_rate_rad_per_s, 0.0);
  EXPECT_EQ(still->value().forward_m_per_s, 0.0);
  std::vector<uint8_t> flat(static_cast<size_t>(kWidth) * kHeight, 50);
  ASSERT_TRUE(Step(vo, flat).ok());
  auto tie = Step(vo, flat);
  ASSERT_TRUE(tie.ok() && tie->has_value());
  EXPECT_EQ(tie->value().turn_rate_rad_per_s, 0.0);
}

TEST_F(OpenRatslamVisualOdometryTest, RegionsThatDoNotFitAreErrors) {
  options_.rotation_right_px = 120;
  OpenRatslamVisualOdometry wide(options_);
  auto e = Step(wide, Frame(0, 0));
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.status().message().find("rotation region [0, 120) x [0, 6) does not fit a 100x12"),
            std::string::npos)
      << e.status().message();
  options_.rotation_right_px = 30;  // 30 columns cannot hold a 39 px search
  OpenRatslamVisualOdometry narrow(options_);
  EXPECT_FALSE(Step(narrow, Frame(0, 0)).ok());
  VisualOdometryOptions bad = options_;
  bad.model = "optical_flow";
  std::string why;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("model: must be constant_speed or openratslam"), std::string::npos);
  bad = options_;
  bad.translation_top_px = 8;
  bad.translation_bottom_px = 8;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("translation_bottom_px: must be -1 or greater than translation_top_px"),
            std::string::npos);
}

}  // namespace
}  // namespace ratslam::sensors
