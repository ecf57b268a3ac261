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

ViewDecision At(double time_s, uint32_t id, bool is_new) { return {time_s, id, is_new, 0.0}; }

// Time memory: a template met at every Wi-Fi scan (4 s apart) recovers between scans at the
// default 0.5 per second, so each match injects the first-match energy; under frame memory the
// second match in a row injects nothing (the decay formula's numbers as in the test above).
TEST(LocalViewCellsTest, TimeMemoryRecoversPerSecondNotPerFrame) {
  LocalViewOptions options;
  options.memory = ViewMemory::kTime;
  options.skip_recent_s = 0.0;
  LocalViewCells cells(options, 36);
  ASSERT_TRUE(cells.Observe(At(0.0, 0, true), {4, 5, 6}).ok());
  const double first = 0.15 * (30.0 - std::exp(1.2 * 2.0)) / 30.0;
  for (int k = 1; k <= 5; ++k) {
    auto injection = cells.Observe(At(4.0 * k, 0, false), {});
    ASSERT_TRUE(injection.value().has_value()) << k;
    EXPECT_NEAR(injection.value()->energy, first, 1e-12) << k;
  }
  // Two matches 1 s apart: decay 2 - 0.5 + 1 = 2.5 -> E = 0.15 (30 - e^3) / 30; a third at the
  // same instant: 3.5 -> e^4.2 > 30, nothing.
  ASSERT_TRUE(cells.Observe(At(30.0, 0, false), {}).value().has_value());
  auto second = cells.Observe(At(31.0, 0, false), {});
  ASSERT_TRUE(second.value().has_value());
  EXPECT_NEAR(second.value()->energy, 0.15 * (30.0 - std::exp(1.2 * 2.5)) / 30.0, 1e-12);
  EXPECT_FALSE(cells.Observe(At(31.0, 0, false), {}).value().has_value());
  // Frame memory on the same sequence: the second match in a row is exhausted.
  LocalViewCells frames(LocalViewOptions{.skip_recent_templates = 0}, 36);
  ASSERT_TRUE(frames.Observe(At(0.0, 0, true), {4, 5, 6}).ok());
  EXPECT_TRUE(frames.Observe(At(4.0, 0, false), {}).value().has_value());
  EXPECT_FALSE(frames.Observe(At(8.0, 0, false), {}).value().has_value());
}

// Time memory: youth is by data time, not by how many templates came after.
TEST(LocalViewCellsTest, TimeMemorySkipsTemplatesYoungerThanSkipRecentS) {
  LocalViewOptions options;
  options.memory = ViewMemory::kTime;
  options.skip_recent_s = 10.0;
  LocalViewCells cells(options, 36);
  ASSERT_TRUE(cells.Observe(At(0.0, 0, true), {1, 0, 0}).ok());
  EXPECT_FALSE(cells.Observe(At(9.9, 0, false), {}).value().has_value());
  EXPECT_TRUE(cells.Observe(At(20.0, 0, false), {}).value().has_value());
  // Many newer templates do not make template 0 recent (frame memory: the 10 newest).
  for (uint32_t i = 1; i <= 20; ++i) ASSERT_TRUE(cells.Observe(At(20.0 + i, i, true), {}).ok());
  EXPECT_TRUE(cells.Observe(At(45.0, 0, false), {}).value().has_value());
  EXPECT_FALSE(cells.Observe(At(45.0, 20, false), {}).value().has_value());  // made at 40 s
}

TEST(LocalViewCellsTest, MemoryNamesRoundTrip) {
  for (ViewMemory m : {ViewMemory::kFrames, ViewMemory::kTime}) {
    EXPECT_EQ(ViewMemoryFromString(ToString(m)).value(), m);
  }
  EXPECT_FALSE(ViewMemoryFromString("seconds").ok());
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
