#include "ratslam/local_view_cells.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace ratslam {
namespace {

TEST(LocalViewOptionsTest, DefaultsAreValid) {
  std::string error;
  EXPECT_TRUE(LocalViewOptions().IsValid(&error)) << error;
}

ViewDecision New(uint32_t id) { return {0.0, id, true, 0.0}; }
ViewDecision Seen(uint32_t id, double heading_change_rad = 0.0) {
  return {0.0, id, false, heading_change_rad};
}

TEST(LocalViewCellsTest, NewTemplatesMustHaveConsecutiveIds) {
  LocalViewCells cells(LocalViewOptions(), 36);
  EXPECT_TRUE(cells.Observe(New(0), {1, 2, 3}).ok());
  EXPECT_FALSE(cells.Observe(New(5), {1, 2, 3}).ok());
  EXPECT_FALSE(cells.Observe(Seen(9), {1, 2, 3}).ok());
  EXPECT_EQ(cells.size(), 1u);
}

TEST(LocalViewCellsTest, RecentTemplatesDoNotInject) {
  LocalViewOptions options;
  options.skip_recent_templates = 3;
  LocalViewCells cells(options, 36);
  for (uint32_t i = 0; i < 4; ++i) ASSERT_TRUE(cells.Observe(New(i), {double(i), 0, 0}).ok());
  // Templates 1..3 are the three newest: no injection. Template 0 is old enough.
  EXPECT_FALSE(cells.Observe(Seen(1), {}).value().has_value());
  auto injection = cells.Observe(Seen(0), {});
  ASSERT_TRUE(injection.ok());
  ASSERT_TRUE(injection.value().has_value());
  EXPECT_EQ(injection.value()->position.x, 0.0);
}

TEST(LocalViewCellsTest, EnergyFollowsDecayFormulaAndRecovers) {
  LocalViewOptions options;
  options.skip_recent_templates = 0;
  LocalViewCells cells(options, 36);
  ASSERT_TRUE(cells.Observe(New(0), {4, 5, 6}).ok());
  // First match: decay = floor (1) + 1 = 2 -> E = 0.15 * (30 - e^2.4) / 30.
  auto first = cells.Observe(Seen(0), {});
  ASSERT_TRUE(first.value().has_value());
  EXPECT_NEAR(first.value()->energy, 0.15 * (30.0 - std::exp(2.4)) / 30.0, 1e-12);
  // Immediate repeat: decay = 2 - 0.05 + 1 = 2.95 -> e^(3.54) > 30, no energy.
  EXPECT_FALSE(cells.Observe(Seen(0), {}).value().has_value());
  // After 60 frames of rest the decay is back at the floor and the full first energy returns.
  ASSERT_TRUE(cells.Observe(New(1), {}).ok());
  for (int i = 0; i < 60; ++i) ASSERT_TRUE(cells.Observe(Seen(1), {}).ok());
  auto rested = cells.Observe(Seen(0), {});
  ASSERT_TRUE(rested.value().has_value());
  EXPECT_NEAR(rested.value()->energy, first.value()->energy, 1e-12);
}

TEST(LocalViewCellsTest, HeadingChangeShiftsInjectionTheta) {
  LocalViewOptions options;
  options.skip_recent_templates = 0;
  LocalViewCells cells(options, 36);
  ASSERT_TRUE(cells.Observe(New(0), {1, 1, 35}).ok());
  auto injection = cells.Observe(Seen(0, std::numbers::pi / 2), {});  // +9 cells, wraps
  ASSERT_TRUE(injection.value().has_value());
  EXPECT_NEAR(injection.value()->position.theta, 8.0, 1e-9);
}

}  // namespace
}  // namespace ratslam
