// ROS 2 bags written by independent writers (Foxglove's MCAP writer and CDR serialiser, SQLite,
// through scripts/ros2_fixtures.sh) read back through our MCAP, CDR and rosbag2 readers; CDR
// written by hand; damaged files fail with messages naming where.
#include "dataset/rosbag2.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "dataset/dataset_loader.h"
#include "dataset/mcap.h"
#include "dataset/ros2_messages.h"
#include "tests/test_paths.h"

namespace ratslam::dataset {
namespace {
namespace fs = std::filesystem;

std::vector<uint8_t> Slurp(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void Spit(const fs::path& file, const std::vector<uint8_t>& bytes) {
  std::ofstream(file, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
}

// The byte offset of the first MCAP record with `opcode` (walking from the magic), or 0.
size_t FindRecord(const std::vector<uint8_t>& file, uint8_t opcode) {
  size_t at = 8;
  while (at + 9 <= file.size()) {
    uint64_t length = 0;
    for (int k = 0; k < 8; ++k)
      length |= uint64_t{file[at + 1 + static_cast<size_t>(k)]} << (8 * k);
    if (file[at] == opcode) return at;
    if (length > file.size() - at - 9) return 0;
    at += 9 + length;
  }
  return 0;
}

class Rosbag2Test : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = fs::temp_directory_path() /
              ("ratslam_rosbag2_test_" + std::to_string(::getpid()) + "_" +
               ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(folder_);
    fs::create_directories(folder_);
  }
  void TearDown() override { fs::remove_all(folder_); }

  // Runs the fixture script; false (with the reason in *why) when it cannot run here.
  bool MakeFixtures(const fs::path& out, const std::string& data, std::string* why) {
    const fs::path log = folder_ / "fixtures.log";
    const std::string command = "bash " + std::string(ratslam::test_paths::SourceDir()) +
                                "/scripts/ros2_fixtures.sh " + out.string() + " " + data + " 2>" +
                                log.string();
    const int rc = std::system(command.c_str());
    const std::vector<uint8_t> text = Slurp(log);
    *why = std::string(text.begin(), text.end());
    if (WIFEXITED(rc) && WEXITSTATUS(rc) == 77) return false;
    EXPECT_EQ(rc, 0) << *why;
    return rc == 0;
  }

  fs::path folder_;
};

#define MAKE_FIXTURES_OR_SKIP(out, data)                                       \
  do {                                                                         \
    std::string why;                                                           \
    if (!MakeFixtures(out, data, &why)) {                                      \
      if (::testing::Test::HasFailure()) return;                               \
      GTEST_SKIP() << "ROS 2 bags from independent writers not made: " << why; \
    }                                                                          \
  } while (0)

// The fixture's raw images, IMU and odometry, with the values the writer was given.
TEST_F(Rosbag2Test, RawImagesImuAndOdometryFromAnIndependentWriter) {
  MAKE_FIXTURES_OR_SKIP(folder_ / "fx", "");
  BagTopics topics;
  topics.imu_topic = "/imu";
  for (const char* name :
       {"raw_lz4.mcap", "raw_nosummary.mcap", "raw_channels_only.mcap", "raw_db3"}) {
    const std::string bag = (folder_ / "fx" / name).string();
    ASSERT_TRUE(LooksLikeRos2Bag(bag)) << name;
    StatusOr<Dataset> d = ReadRos2Bag(bag, topics);
    ASSERT_TRUE(d.ok()) << d.status().message();
    FileImageLoader loader;
    ASSERT_EQ(d->images.size(), 3u);
    StatusOr<GrayImage> image = loader.Load(d->ImagePath(d->images[2]));
    ASSERT_TRUE(image.ok()) << image.status().message();
    EXPECT_EQ(image->pixels.size(), 4u) << name;
  }
  const std::string bag = (folder_ / "fx" / "raw.mcap").string();
  ASSERT_TRUE(LooksLikeRos2Bag(bag));
  StatusOr<Dataset> d = ReadRos2Bag(bag, topics);
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_EQ(d->images.size(), 3u);
  EXPECT_DOUBLE_EQ(d->images[1].time_s, 0.1);
  EXPECT_DOUBLE_EQ(d->images[2].time_s, 0.2);
  ASSERT_EQ(d->odometry.size(), 1u);
  EXPECT_DOUBLE_EQ(d->odometry[0].time_s, 0.2);
  EXPECT_EQ(d->odometry[0].forward_speed_m_per_s, 0.5);
  EXPECT_EQ(d->odometry[0].turn_rate_rad_per_s, -0.25);
  ASSERT_EQ(d->compass.size(), 1u);
  EXPECT_DOUBLE_EQ(d->compass[0].time_s, 0.1);
  EXPECT_NEAR(d->compass[0].heading_rad, 0.75, 1e-12);

  FileImageLoader loader;
  StatusOr<GrayImage> mono = loader.Load(d->ImagePath(d->images[0]));
  ASSERT_TRUE(mono.ok()) << mono.status().message();
  EXPECT_EQ(mono->width, 3);
  EXPECT_EQ(mono->height, 2);
  EXPECT_EQ(mono->pixels, (std::vector<uint8_t>{0, 50, 100, 150, 200, 250}));
  // Pure red, green, blue and white: ITU-R BT.601 luma 0.299 R + 0.587 G + 0.114 B.
  const std::vector<int> luma = {76, 150, 29, 255};
  for (size_t i : {size_t{1}, size_t{2}}) {  // rgb8 with row padding, then bgr8
    StatusOr<GrayImage> colour = loader.Load(d->ImagePath(d->images[i]));
    ASSERT_TRUE(colour.ok()) << colour.status().message();
    ASSERT_EQ(colour->pixels.size(), 4u);
    for (size_t p = 0; p < 4; ++p) EXPECT_NEAR(colour->pixels[p], luma[p], 1) << i << " " << p;
  }
  // As stored for `import`: a raw image becomes a lossless PNG of the same grey pixels.
  Ros2ImageReader reader;
  StatusOr<EncodedImage> png = reader.Encoded(d->ImagePath(d->images[0]));
  ASSERT_TRUE(png.ok()) << png.status().message();
  EXPECT_EQ(png->extension, "png");
  const cv::Mat decoded = cv::imdecode(png->bytes, cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(decoded.total(), 6u);
  EXPECT_EQ(std::vector<uint8_t>(decoded.datastart, decoded.dataend), mono->pixels);
}

// A replay folder written by us, turned into six ROS 2 bags by the independent writers (zstd,
// lz4 and uncompressed chunks, no chunks and no summary, a sqlite3 folder, an MCAP folder): every
// one reads back to the folder's streams, exactly, and its images to the folder's pixels.
TEST_F(Rosbag2Test, EveryStorageAndCompressionReadsBackTheFolder) {
  Dataset d;
  std::mt19937 random(7);
  fs::create_directories(folder_ / "data" / "images");
  for (int i = 0; i < 40; ++i) {
    const double t = i / 10.0;
    ImageRow image;
    image.time_s = t;
    image.file = std::to_string(i) + ".png";
    d.images.push_back(image);
    cv::Mat pixels(6, 9, CV_8U);
    for (auto it = pixels.begin<uint8_t>(); it != pixels.end<uint8_t>(); ++it) {
      *it = static_cast<uint8_t>(random());
    }
    ASSERT_TRUE(cv::imwrite((folder_ / "data" / "images" / image.file).string(), pixels));
    d.odometry.push_back({t, 0.25 + i / 64.0, -0.5 + i / 32.0});
    d.ground_truth.push_back({t, i * 1.5, -0.25 * i, 0.05 * i - 1.0, 0});
  }
  ASSERT_TRUE(WriteDataset(d, (folder_ / "data").string()).ok());
  MAKE_FIXTURES_OR_SKIP(folder_ / "fx", (folder_ / "data").string());
  BagTopics topics;
  topics.ground_truth_topic = "/ground_truth";
  topics.imu_topic = "imu";
  FileImageLoader loader;
  for (const char* name : {"loop_zstd.mcap", "loop_lz4.mcap", "loop_plain.mcap",
                           "loop_nosummary.mcap", "loop_db3", "loop_mcap_dir"}) {
    SCOPED_TRACE(name);
    const std::string bag = (folder_ / "fx" / name).string();
    StatusOr<DatasetFormat> format = DetectDatasetFormat(bag);
    ASSERT_TRUE(format.ok()) << format.status().message();
    EXPECT_EQ(*format, DatasetFormat::kRos2Bag);
    StatusOr<Dataset> got = ReadRos2Bag(bag, topics);
    ASSERT_TRUE(got.ok()) << got.status().message();
    ASSERT_EQ(got->images.size(), d.images.size());
    ASSERT_EQ(got->odometry.size(), d.odometry.size());
    ASSERT_EQ(got->ground_truth.size(), d.ground_truth.size());
    ASSERT_EQ(got->compass.size(), d.ground_truth.size());
    for (size_t i = 0; i < d.images.size(); ++i) {
      EXPECT_EQ(got->images[i].time_s, d.images[i].time_s) << i;
      EXPECT_EQ(got->odometry[i].time_s, d.odometry[i].time_s) << i;
      EXPECT_EQ(got->odometry[i].forward_speed_m_per_s, d.odometry[i].forward_speed_m_per_s);
      EXPECT_EQ(got->odometry[i].turn_rate_rad_per_s, d.odometry[i].turn_rate_rad_per_s);
      EXPECT_EQ(got->ground_truth[i].x_m, d.ground_truth[i].x_m);
      EXPECT_EQ(got->ground_truth[i].y_m, d.ground_truth[i].y_m);
      EXPECT_NEAR(got->ground_truth[i].theta_rad, d.ground_truth[i].theta_rad, 1e-12);
      EXPECT_NEAR(got->compass[i].heading_rad, d.ground_truth[i].theta_rad, 1e-12);
      StatusOr<GrayImage> from_bag = loader.Load(got->ImagePath(got->images[i]));
      StatusOr<GrayImage> from_folder =
          loader.Load((folder_ / "data" / "images" / d.images[i].file).string());
      ASSERT_TRUE(from_bag.ok()) << from_bag.status().message();
      ASSERT_TRUE(from_folder.ok());
      EXPECT_EQ(from_bag->pixels, from_folder->pixels) << i;
    }
  }
  StatusOr<std::unique_ptr<McapReader>> indexed =
      McapReader::Open((folder_ / "fx" / "loop_zstd.mcap").string());
  StatusOr<std::unique_ptr<McapReader>> scanned =
      McapReader::Open((folder_ / "fx" / "loop_nosummary.mcap").string());
  ASSERT_TRUE(indexed.ok() && scanned.ok());
  EXPECT_TRUE((*indexed)->has_summary());
  EXPECT_FALSE((*scanned)->has_summary());
  EXPECT_EQ((*indexed)->profile(), "ros2");

  // Cut anywhere, an MCAP file is an error, never a shorter data set.
  const std::vector<uint8_t> whole = Slurp(folder_ / "fx" / "loop_lz4.mcap");
  const fs::path cut = folder_ / "cut.mcap";
  for (size_t length :
       {size_t{8}, size_t{100}, whole.size() / 2, whole.size() - 9, whole.size() - 1}) {
    Spit(cut, std::vector<uint8_t>(whole.begin(), whole.begin() + static_cast<ptrdiff_t>(length)));
    StatusOr<Dataset> got = ReadRos2Bag(cut.string(), topics);
    ASSERT_FALSE(got.ok()) << length;
    EXPECT_NE(got.status().message().find("truncated"), std::string::npos)
        << got.status().message();
  }
  // The summary must agree with the records: a Statistics record counting one message more is
  // refused, and so is a chunk whose records were changed (its CRC no longer matches).
  const std::vector<uint8_t> zstd = Slurp(folder_ / "fx" / "loop_zstd.mcap");
  const size_t statistics = FindRecord(zstd, 0x0B);
  ASSERT_NE(statistics, 0u);
  std::vector<uint8_t> miscounted = zstd;
  ++miscounted[statistics + 9];  // message_count, little-endian
  Spit(cut, miscounted);
  StatusOr<Dataset> got = ReadRos2Bag(cut.string(), topics);
  ASSERT_FALSE(got.ok());
  EXPECT_NE(got.status().message().find("(Statistics record): message_count"), std::string::npos)
      << got.status().message();
  const std::vector<uint8_t> plain = Slurp(folder_ / "fx" / "loop_plain.mcap");
  const size_t chunk = FindRecord(plain, 0x06);
  ASSERT_NE(chunk, 0u);
  std::vector<uint8_t> changed = plain;
  changed[chunk + 200] ^= 0x01;  // inside the first image's PNG bytes
  Spit(cut, changed);
  got = ReadRos2Bag(cut.string(), topics);
  ASSERT_FALSE(got.ok());
  EXPECT_NE(got.status().message().find("byte " + std::to_string(chunk) +
                                        " (Chunk record): uncompressed_crc"),
            std::string::npos)
      << got.status().message();
}

// Bytes written by hand after the CDR rules: a big-endian PoseStamped (alignment counted from
// after the 4-byte encapsulation header: the doubles start at offset 24 of the body).
TEST(Ros2MessagesTest, BigEndianPoseStampedByHand) {
  std::vector<uint8_t> bytes = {0x00, 0x00, 0x00, 0x00};  // CDR_BE, options
  auto u32 = [&](uint32_t v) {
    for (int k = 3; k >= 0; --k) bytes.push_back(static_cast<uint8_t>(v >> (8 * k)));
  };
  auto f64 = [&](double v) {
    uint64_t bits = 0;
    std::memcpy(&bits, &v, 8);
    for (int k = 7; k >= 0; --k) bytes.push_back(static_cast<uint8_t>(bits >> (8 * k)));
  };
  u32(17);         // sec
  u32(250000000);  // nanosec
  u32(4);          // frame_id length with NUL
  for (char c : std::string("map")) bytes.push_back(static_cast<uint8_t>(c));
  bytes.push_back(0);
  while ((bytes.size() - 4) % 8 != 0) bytes.push_back(0xEE);  // padding to the doubles
  EXPECT_EQ(bytes.size(), 4u + 16u);
  f64(1.5);
  f64(-2.25);
  f64(0.0);
  f64(0.0);
  f64(0.0);
  f64(std::sin(0.3));
  f64(std::cos(0.3));
  StatusOr<Ros2PoseStamped> pose = DecodeRos2PoseStamped(bytes.data(), bytes.size(), "hand");
  ASSERT_TRUE(pose.ok()) << pose.status().message();
  EXPECT_EQ(pose->stamp.Nanoseconds(), 17250000000);
  EXPECT_EQ(pose->x_m, 1.5);
  EXPECT_EQ(pose->y_m, -2.25);
  EXPECT_EQ(pose->orientation.z, std::sin(0.3));
  // Every shorter prefix is an error naming a field; a wrong encapsulation is named as such.
  for (size_t n = 0; n < bytes.size(); ++n) {
    StatusOr<Ros2PoseStamped> cut = DecodeRos2PoseStamped(bytes.data(), n, "hand");
    ASSERT_FALSE(cut.ok()) << n;
    EXPECT_EQ(cut.status().message().rfind("hand: ", 0), 0u) << cut.status().message();
  }
  bytes[1] = 0x02;
  StatusOr<Ros2PoseStamped> pl = DecodeRos2PoseStamped(bytes.data(), bytes.size(), "hand");
  ASSERT_FALSE(pl.ok());
  EXPECT_NE(pl.status().message().find("not plain CDR"), std::string::npos);
}

TEST(Ros2MessagesTest, ALengthBeyondTheMessageNamesItsField) {
  // Little-endian CompressedImage whose data claims 4 GB.
  std::vector<uint8_t> bytes = {0x00, 0x01, 0x00, 0x00, 1,   0, 0,    0,    0,    0,   0,
                                0,    1,    0,    0,    0,   0, 0,    0,    0,    4,   0,
                                0,    0,    'p',  'n',  'g', 0, 0xff, 0xff, 0xff, 0xff};
  StatusOr<Ros2CompressedImage> m = DecodeRos2CompressedImage(bytes.data(), bytes.size(), "w");
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.status().message().find("field data: runs past the end"), std::string::npos)
      << m.status().message();
}

TEST_F(Rosbag2Test, NotABagAndBrokenFoldersAreNamed) {
  Spit(folder_ / "x.mcap", {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n', 1, 2, 3});
  StatusOr<Dataset> d = ReadRos2Bag((folder_ / "x.mcap").string(), {});
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.status().message().find("truncated MCAP"), std::string::npos);
  fs::create_directories(folder_ / "bag");
  std::ofstream(folder_ / "bag" / "metadata.yaml")
      << "rosbag2_bagfile_information:\n  storage_identifier: sqlite3\n  relative_file_paths:\n"
         "    - ../../etc/passwd\n";
  d = ReadRos2Bag((folder_ / "bag").string(), {});
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.status().message().find("metadata.yaml: line 4"), std::string::npos)
      << d.status().message();
  std::ofstream(folder_ / "bag" / "metadata.yaml")
      << "rosbag2_bagfile_information:\n  storage_identifier: sqlite3\n  relative_file_paths:\n"
         "    - bag_0.db3\n";
  Spit(folder_ / "bag" / "bag_0.db3", {'n', 'o', 't'});
  d = ReadRos2Bag((folder_ / "bag").string(), {});
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.status().message().find("bag_0.db3 is missing or not a sqlite3 file"),
            std::string::npos)
      << d.status().message();
}

}  // namespace
}  // namespace ratslam::dataset
