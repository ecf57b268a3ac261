#include "apps/demo_config.h"

#include <gtest/gtest.h>

#include "fusion/io/config.h"

namespace ratslam {
namespace {

TEST(DemoConfigTest, CommittedDemoTomlEqualsBuiltInDemoConfig) {
  StatusOr<PipelineOptions> committed =
      LoadConfigFile(std::string(RATSLAM_SOURCE_DIR) + "/configs/demo.toml");
  ASSERT_TRUE(committed.ok()) << committed.status().message();
  EXPECT_EQ(PrintConfig(committed.value()), PrintConfig(DemoPipelineOptions()));
}

TEST(DemoConfigTest, CommittedDefaultTomlEqualsDefaults) {
  StatusOr<PipelineOptions> committed =
      LoadConfigFile(std::string(RATSLAM_SOURCE_DIR) + "/configs/default.toml");
  ASSERT_TRUE(committed.ok()) << committed.status().message();
  EXPECT_EQ(PrintConfig(committed.value()), PrintConfig(PipelineOptions()));
}

TEST(DemoConfigTest, DemoOptionsAreValid) {
  std::string error;
  EXPECT_TRUE(DemoPipelineOptions().IsValid(&error)) << error;
  EXPECT_TRUE(DemoSyntheticOptions().IsValid(&error)) << error;
}

}  // namespace
}  // namespace ratslam
