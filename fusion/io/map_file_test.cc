#include "fusion/io/map_file.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace ratslam {
namespace {

MapFile SampleMap() {
  // A small but complete state, produced by running the spine.
  Ratslam slam({});
  for (uint32_t i = 0; i < 30; ++i) {
    EXPECT_TRUE(slam.OnView({i * 0.1, i % 20, i < 20, 0.0}).ok());
    EXPECT_TRUE(slam.OnOdometry({i * 0.1, 0.5, 0.05}).ok());
  }
  MapFile map;
  map.config_fingerprint = 0x1234;
  map.dataset_name = "sample";
  map.state.ratslam = slam.GetState();
  map.state.front_end = std::string(1280, '\x07');
  map.state.next_event = 60;
  map.state.events_total = 100;
  map.state.trajectory.push_back({0.1, 3, {1, 2, 3}, 4, 5, 6});
  map.state.frames.push_back({0.1, 3, true, 2});
  return map;
}

TEST(MapFileTest, EncodeDecodeIsExact) {
  const MapFile map = SampleMap();
  const std::string bytes = EncodeMapFile(map);
  StatusOr<MapFile> back = DecodeMapFile(bytes, "m");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(EncodeMapFile(back.value()), bytes);
  EXPECT_EQ(back->dataset_name, "sample");
  EXPECT_EQ(back->state.ratslam.experience_map.experiences.size(),
            map.state.ratslam.experience_map.experiences.size());
  Ratslam restored({});
  EXPECT_TRUE(restored.SetState(back->state.ratslam).ok());
}

TEST(MapFileTest, EveryTruncationIsAnErrorNotACrash) {
  const std::string bytes = EncodeMapFile(SampleMap());
  for (size_t length = 0; length < bytes.size(); length += 1 + length / 50) {
    StatusOr<MapFile> map = DecodeMapFile(bytes.substr(0, length), "m");
    EXPECT_FALSE(map.ok()) << "length " << length;
  }
}

TEST(MapFileTest, CorruptCountsAndTrailingBytesAreErrors) {
  std::string bytes = EncodeMapFile(SampleMap());
  std::string huge = bytes;
  // The first count after the header (pose-cell indices) set to an absurd value.
  const size_t count_at = 8 + 4 + 8 + 8 + std::string("sample").size();
  for (int i = 0; i < 8; ++i) huge[count_at + i] = '\xff';
  StatusOr<MapFile> a = DecodeMapFile(huge, "m");
  ASSERT_FALSE(a.ok());
  EXPECT_NE(a.status().message().find("exceeds the file size"), std::string::npos)
      << a.status().message();
  EXPECT_FALSE(DecodeMapFile(bytes + "x", "m").ok());
  EXPECT_FALSE(DecodeMapFile("not a map", "m").ok());
}

TEST(MapFileTest, SaveIsAtomicAndLoads) {
  const auto path = std::filesystem::temp_directory_path() / "ratslam_map_file_test.map";
  ASSERT_TRUE(SaveMapFile(SampleMap(), path.string()).ok());
  StatusOr<MapFile> back = LoadMapFile(path.string());
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->state.next_event, 60u);
  for (const auto& entry : std::filesystem::directory_iterator(path.parent_path())) {
    EXPECT_EQ(entry.path().string().find("ratslam_map_file_test.map.tmp"), std::string::npos);
  }
  std::filesystem::remove(path);
  EXPECT_FALSE(LoadMapFile(path.string()).ok());
}

}  // namespace
}  // namespace ratslam
