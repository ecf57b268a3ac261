#include "ratslam/ratslam.h"

#include <gtest/gtest.h>

#include <numbers>

namespace ratslam {
namespace {

TEST(RatslamOptionsTest, DefaultsAreValid) {
  std::string error;
  EXPECT_TRUE(RatslamOptions().IsValid(&error)) << error;
}

TEST(RatslamOptionsTest, ErrorNamesSectionAndField) {
  RatslamOptions options;
  options.action.match_distance_cells = -1;
  std::string error;
  ASSERT_FALSE(options.IsValid(&error));
  EXPECT_EQ(error.rfind("action.match_distance_cells", 0), 0u) << error;
}

TEST(RatslamTest, NewViewsCreateExperiencesAndLinks) {
  Ratslam slam({});
  for (uint32_t i = 0; i < 5; ++i) {
    ASSERT_TRUE(slam.OnView({i * 1.0, i, true, 0.0}).ok());
    auto action = slam.OnOdometry({i * 1.0, 1.0, 0.0});
    ASSERT_TRUE(action.ok());
    EXPECT_EQ(action.value(), ActionKind::kCreatedExperience);
  }
  EXPECT_EQ(slam.experience_map().num_experiences(), 5u);
  EXPECT_EQ(slam.experience_map().num_links(), 4u);
  EXPECT_EQ(slam.counters().loop_closures, 0u);
}

TEST(RatslamTest, RejectsOdometryThatIsNotFinite) {
  Ratslam slam({});
  EXPECT_FALSE(slam.OnOdometry({0.0, std::numeric_limits<double>::quiet_NaN(), 0.0}).ok());
}

TEST(RatslamTest, RevisitedPlaceClosesTheLoop) {
  // Out and back along a line of 30 places 1 m apart, then the same places again in order.
  RatslamOptions options;
  options.local_view.skip_recent_templates = 5;
  Ratslam slam(options);
  double t = 0.0;
  for (uint32_t i = 0; i < 30; ++i, t += 1.0) {
    ASSERT_TRUE(slam.OnView({t, i, true, 0.0}).ok());
    ASSERT_TRUE(slam.OnOdometry({t, 1.0, 0.0}).ok());
  }
  // Drive home with a drifting odometry (teleport back to the start: heading unchanged), then
  // see the first places again; the injections pull the packet back and links close the loop.
  for (int lap = 0; lap < 3; ++lap) {
    for (uint32_t i = 0; i < 30; ++i, t += 1.0) {
      ASSERT_TRUE(slam.OnView({t, i, false, 0.0}).ok());
      ASSERT_TRUE(slam.OnOdometry({t, 1.0, 0.0}).ok());
    }
  }
  EXPECT_GT(slam.counters().loop_closures, 0u);
  EXPECT_GT(slam.counters().injections, 0u);
}

TEST(RatslamTest, StateRoundTripContinuesIdentically) {
  Ratslam a({});
  for (uint32_t i = 0; i < 20; ++i) {
    ASSERT_TRUE(a.OnView({i * 1.0, i % 12, i < 12, 0.0}).ok());
    ASSERT_TRUE(a.OnOdometry({i * 1.0, 0.8, 0.1}).ok());
  }
  Ratslam b({});
  ASSERT_TRUE(b.SetState(a.GetState()).ok());
  for (uint32_t i = 20; i < 40; ++i) {
    for (Ratslam* s : {&a, &b}) {
      ASSERT_TRUE(s->OnView({i * 1.0, i % 12, false, 0.0}).ok());
      ASSERT_TRUE(s->OnOdometry({i * 1.0, 0.8, 0.1}).ok());
    }
  }
  ASSERT_EQ(a.experience_map().num_experiences(), b.experience_map().num_experiences());
  for (size_t i = 0; i < a.experience_map().num_experiences(); ++i) {
    EXPECT_EQ(a.experience_map().experience(i).x_m, b.experience_map().experience(i).x_m);
  }
}

TEST(RatslamTest, FailedSetStateChangesNothing) {
  Ratslam a({});
  for (uint32_t i = 0; i < 5; ++i) {
    ASSERT_TRUE(a.OnView({i * 1.0, i, true, 0.0}).ok());
    ASSERT_TRUE(a.OnOdometry({i * 1.0, 1.0, 0.0}).ok());
  }
  Ratslam::State bad = a.GetState();
  bad.experience_map.links.push_back(
      {99, 0, 1234, 1.0, 0.0, 0.0, 1.0, false});  // no such experience
  Ratslam b({});
  const auto before = b.pose_cells().BestPosition();
  EXPECT_FALSE(b.SetState(bad).ok());
  EXPECT_EQ(b.local_view().size(), 0u);  // the valid parts were not applied either
  EXPECT_EQ(b.experience_map().num_experiences(), 0u);
  EXPECT_EQ(b.pose_cells().BestPosition().x, before.x);
}

}  // namespace
}  // namespace ratslam
