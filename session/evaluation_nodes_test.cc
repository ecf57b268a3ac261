#include "session/evaluation_nodes.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace ratslam {
namespace {

TEST(EvaluationNodesTest, LoadsAnImageFolderWithFloors) {
  const std::string path = std::string(RATSLAM_SHARED_DATA_DIR) + "/multifloor-corridors";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path;
  fabmap::EvaluationOptions options;
  options.frame_spacing_m = 0.5;
  const auto nodes = LoadEvaluationNodes(path, true, true, options, {});
  ASSERT_TRUE(nodes.ok()) << nodes.status().message();
  ASSERT_EQ(nodes->size(), 1500u);
  EXPECT_EQ(nodes->front().floor, 1);
  EXPECT_EQ(nodes->back().floor, 3);
  EXPECT_DOUBLE_EQ((*nodes)[1].x_m, 0.5);
  EXPECT_FALSE(nodes->front().wifi.has_value());
}

TEST(EvaluationNodesTest, BadPathsAndOptionsAreErrors) {
  fabmap::EvaluationOptions options;
  const auto missing = LoadEvaluationNodes("/no/such/place", true, false, options, {});
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("/no/such/place"), std::string::npos);
  options.map_fraction = 1.5;
  EXPECT_FALSE(LoadEvaluationNodes(RATSLAM_SOURCE_DIR, true, false, options, {}).ok());
}

}  // namespace
}  // namespace ratslam
