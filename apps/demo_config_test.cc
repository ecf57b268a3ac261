#include "apps/demo_config.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "io/config.h"
#include "tests/test_paths.h"

namespace ratslam::apps {
namespace {

TEST(DemoConfigTest, CommittedDemoTomlEqualsBuiltInDemoConfig) {
  StatusOr<fusion::PipelineOptions> committed =
      io::LoadConfigFile(std::string(ratslam::test_paths::SourceDir()) + "/configs/demo.toml");
  ASSERT_TRUE(committed.ok()) << committed.status().message();
  EXPECT_EQ(io::PrintConfig(committed.value()), io::PrintConfig(DemoPipelineOptions()));
}

TEST(DemoConfigTest, CommittedSyntheticTomlEqualsBuiltInSyntheticConfig) {
  StatusOr<fusion::PipelineOptions> committed =
      io::LoadConfigFile(std::string(ratslam::test_paths::SourceDir()) + "/configs/synthetic.toml");
  ASSERT_TRUE(committed.ok()) << committed.status().message();
  EXPECT_EQ(io::PrintConfig(committed.value()), io::PrintConfig(SyntheticPipelineOptions()));
}

// default.toml is what `ratslam print-config` prints, byte for byte: every key (it once lacked
// two added keys, which loading alone cannot notice), its documentation, unit and range.
TEST(DemoConfigTest, CommittedDefaultTomlIsThePrintedDefaults) {
  const std::string path = std::string(ratslam::test_paths::SourceDir()) + "/configs/default.toml";
  std::ifstream in(path);
  ASSERT_TRUE(in) << path;
  const std::string committed((std::istreambuf_iterator<char>(in)), {});
  EXPECT_EQ(committed, io::PrintConfig(fusion::PipelineOptions()))
      << "regenerate with: ratslam print-config > configs/default.toml";
}

TEST(DemoConfigTest, DemoOptionsAreValid) {
  std::string error;
  EXPECT_TRUE(DemoPipelineOptions().IsValid(&error)) << error;
  EXPECT_TRUE(SyntheticPipelineOptions().IsValid(&error)) << error;
  EXPECT_TRUE(DemoSyntheticOptions().IsValid(&error)) << error;
}

}  // namespace
}  // namespace ratslam::apps
