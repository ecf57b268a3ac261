#include "viewer/figures.h"

#include <gtest/gtest.h>

namespace ratslam {
namespace {

TEST(NiceStepTest, PicksOneTwoFive) {
  EXPECT_DOUBLE_EQ(NiceStep(100, 10), 10);
  EXPECT_DOUBLE_EQ(NiceStep(37, 8), 5);
  EXPECT_DOUBLE_EQ(NiceStep(0.9, 5), 0.2);
}

}  // namespace
}  // namespace ratslam
