#include "io/map_file.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "common/checksum.h"
#include "common/scratch_dir.h"
#include "io/state_schema.h"

namespace ratslam::io {
namespace {

// One fresh folder per test process (two checkouts testing at once never collide).
const ScratchDir& TestScratch() {
  static const ScratchDir dir("ratslam_test");
  return dir;
}

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
  // With a matching checksum, so that the count itself is what the reader meets.
  huge.resize(huge.size() - 4);
  AppendChecksum(&huge);
  StatusOr<MapFile> a = DecodeMapFile(huge, "m");
  ASSERT_FALSE(a.ok());
  EXPECT_NE(a.status().message().find("exceeds the file size"), std::string::npos)
      << a.status().message();
  EXPECT_FALSE(DecodeMapFile(bytes + "x", "m").ok());
  EXPECT_FALSE(DecodeMapFile("not a map", "m").ok());
}

TEST(MapFileTest, EverySingleByteChangeIsAnError) {
  const std::string bytes = EncodeMapFile(SampleMap());
  for (size_t i = 0; i < bytes.size(); i += 1 + i / 64) {
    std::string flipped = bytes;
    flipped[i] = static_cast<char>(flipped[i] ^ 0x64);
    StatusOr<MapFile> map = DecodeMapFile(flipped, "m.map");
    EXPECT_FALSE(map.ok()) << "byte " << i;
  }
  std::string flipped = bytes;
  flipped[bytes.size() / 2] ^= 1;
  StatusOr<MapFile> map = DecodeMapFile(flipped, "m.map");
  ASSERT_FALSE(map.ok());
  EXPECT_NE(map.status().message().find("m.map: checksum mismatch"), std::string::npos)
      << map.status().message();
}

// A map whose checksum is right but whose graph is not (a link to an experience that does not
// exist) is refused by the decoder itself, so no reader of maps (route, call, render) can meet it.
TEST(MapFileTest, ADanglingLinkIsRefusedByEveryReader) {
  MapFile map = SampleMap();
  ASSERT_FALSE(map.state.ratslam.experience_map.links.empty());
  map.state.ratslam.experience_map.links.back().to = 100;
  StatusOr<MapFile> back = DecodeMapFile(EncodeMapFile(map), "m.map");
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.status().message().find("m.map: corrupt map file: experience map state: link"),
            std::string::npos)
      << back.status().message();
}

TEST(MapFileTest, SaveIsAtomicAndLoads) {
  const auto path = TestScratch().path() / "ratslam_map_file_test.map";
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

// The number of members of an aggregate, found by trying brace-initialisation with ever more
// arguments convertible to anything (the technique of Boost.PFR; no code from it). Independent
// of the schema, so it catches a member added to a state struct but not to its Describe.
struct AnyMember {
  template <typename T>
  operator T&() const;  // NOLINT: implicit by design; never defined (unevaluated use only)
  template <typename T>
  operator T&&() const;  // NOLINT
};

template <typename T, typename... Members>
constexpr size_t MemberCount() {
  if constexpr (requires { T{Members{}..., AnyMember{}}; }) {
    return MemberCount<T, Members..., AnyMember>();
  } else {
    return sizeof...(Members);
  }
}

// Counts the fields a Describe function lists (nested objects count once, as one member).
class CountingArchive {
 public:
  uint32_t version() const { return kMapFormatVersion; }  // the version written
  template <typename T>
  bool operator()(T&) {
    ++count;
    return true;
  }
  template <typename T>
  bool Object(T&) {
    ++count;
    return true;
  }
  template <typename T>
  bool Objects(std::vector<T>&, size_t) {
    ++count;
    return true;
  }
  bool Check(bool, const char*) { return true; }
  size_t count = 0;
};

template <typename T>
size_t DescribedCount() {
  T object{};
  CountingArchive archive;
  Describe(archive, object);
  return archive.count;
}

// `header_members`: members the file's header carries outside the schema's body.
template <typename T>
void ExpectSchemaComplete(const char* name, size_t expected_by_hand, size_t header_members = 0) {
  EXPECT_EQ(MemberCount<T>(), expected_by_hand) << name << ": the member count probe is off";
  EXPECT_EQ(DescribedCount<T>() + header_members, MemberCount<T>())
      << name << " has members that state_schema.h does not save";
}

TEST(MapFileTest, SchemaListsEveryMemberOfEverySavedStruct) {
  // The hand counts pin the probe itself: if a struct grows, both this number and the schema
  // must change, and the test says which struct.
  ExpectSchemaComplete<PoseCellPosition>("PoseCellPosition", 3);
  ExpectSchemaComplete<LocalOffset>("LocalOffset", 3);
  ExpectSchemaComplete<PoseCellNetwork::State>("PoseCellNetwork::State", 5);
  ExpectSchemaComplete<ViewTemplate>("ViewTemplate", 8);
  ExpectSchemaComplete<LocalViewCells::State>("LocalViewCells::State", 2);
  ExpectSchemaComplete<Experience>("Experience", 9);
  ExpectSchemaComplete<Link>("Link", 9);
  ExpectSchemaComplete<ExperienceMap::State>("ExperienceMap::State", 6);
  ExpectSchemaComplete<Ratslam::Counters>("Ratslam::Counters", 5);
  ExpectSchemaComplete<Ratslam::State>("Ratslam::State", 6);
  ExpectSchemaComplete<TrajectoryRecord>("TrajectoryRecord", 6);
  ExpectSchemaComplete<FrameRecord>("FrameRecord", 6);
  ExpectSchemaComplete<Pose2>("Pose2", 3);
  ExpectSchemaComplete<wifi_sequence::PoseSignal>("PoseSignal", 2);
  ExpectSchemaComplete<wifi_sequence::SequencePose>("SequencePose", 6);
  ExpectSchemaComplete<wifi_sequence::SequenceCorrespondence>("SequenceCorrespondence", 5);
  ExpectSchemaComplete<wifi_sequence::SequenceLoop>("SequenceLoop", 11);
  ExpectSchemaComplete<wifi_sequence::WifiSequenceLoopCloser::State>(
      "WifiSequenceLoopCloser::State", 8);
  ExpectSchemaComplete<fusion::ReplayPipeline::State>("ReplayPipeline::State", 17);
  ExpectSchemaComplete<MapFile>("MapFile", 5, /*header_members=*/1);  // format_version
}

}  // namespace
}  // namespace ratslam::io
