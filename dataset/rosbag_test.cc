// ROS bags written with librosbag-storage itself (raw and compressed images, odometry, poses),
// read back through our reader; bad bags fail with messages. C++17, like the reader: Debian's
// ROS 1 message headers do not compile as C++20.
#include "dataset/rosbag.h"

#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "dataset/dataset_loader.h"
#include "tests/test_paths.h"

namespace ratslam::dataset {
namespace {
namespace fs = std::filesystem;

// Images made from their index, so that any image can be checked pixel by pixel.
class IndexedImages : public ImageLoader {
 public:
  StatusOr<GrayImage> Load(const std::string& path) override {
    GrayImage image;
    image.width = 7;
    image.height = 5;
    const int seed = std::stoi(path.substr(path.rfind('/') + 1));
    for (int i = 0; i < image.width * image.height; ++i) {
      image.pixels.push_back(static_cast<uint8_t>(seed * 31 + i * 7));
    }
    return image;
  }
};

class RosbagTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!RosbagSupported()) GTEST_SKIP() << "built without librosbag-storage-dev";
    folder_ = fs::temp_directory_path() /
              ("ratslam_rosbag_test_" + std::to_string(::getpid()) + "_" +
               ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(folder_);
    fs::create_directories(folder_);
  }
  void TearDown() override { fs::remove_all(folder_); }
  std::string Path(const std::string& name) const { return (folder_ / name).string(); }

  // A data set of `n` images and odometry rows 0.1 s apart, with ground truth.
  static Dataset Sample(int n) {
    Dataset d;
    d.folder = "/";
    for (int i = 0; i < n; ++i) {
      const double t = 0.1 * i;
      d.images.push_back({t, std::to_string(i), i + 2});
      d.odometry.push_back({t + 0.05, 0.5 + 0.01 * i, -0.2 + 0.03 * i});
      d.ground_truth.push_back({t, 1.5 * i, -0.25 * i, 0.3 * i - 1.0, 0});
    }
    return d;
  }
  std::string ReadError(const std::string& bag, const BagTopics& topics = {}) {
    StatusOr<Dataset> d = ReadRosbag(bag, topics);
    EXPECT_FALSE(d.ok());
    return d.ok() ? "" : d.status().message();
  }

  fs::path folder_;
};

TEST_F(RosbagTest, WrittenDataSetReadsBackToTheNanosecondAndPixel) {
  const Dataset d = Sample(40);
  IndexedImages images;
  BagTopics topics{"/robot/camera/image/compressed", "/robot/odom", "/overhead/pose", ""};
  ASSERT_TRUE(WriteRosbag(d, &images, topics, Path("a.bag")).ok());
  EXPECT_FALSE(fs::exists(Path("a.bag.partial")));
  // OpenRatSLAM's style of naming: the topic without "/compressed" finds the compressed one.
  topics.image_topic = "robot//camera/image";
  StatusOr<Dataset> r = ReadRosbag(Path("a.bag"), topics);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->name, "a");
  ASSERT_EQ(r->images.size(), d.images.size());
  ASSERT_EQ(r->odometry.size(), d.odometry.size());
  ASSERT_EQ(r->ground_truth.size(), d.ground_truth.size());
  FileImageLoader loader;
  for (size_t i = 0; i < d.images.size(); ++i) {
    EXPECT_NEAR(r->images[i].time_s, d.images[i].time_s, 1e-9);
    StatusOr<GrayImage> got = loader.Load(r->ImagePath(r->images[i]));
    ASSERT_TRUE(got.ok()) << got.status().message();
    EXPECT_EQ(got->pixels, images.Load(std::to_string(i))->pixels) << i;
    EXPECT_EQ(got->width, 7);
  }
  for (size_t i = 0; i < d.odometry.size(); ++i) {
    EXPECT_NEAR(r->odometry[i].time_s, d.odometry[i].time_s, 1e-9);
    EXPECT_EQ(r->odometry[i].forward_speed_m_per_s, d.odometry[i].forward_speed_m_per_s);
    EXPECT_EQ(r->odometry[i].turn_rate_rad_per_s, d.odometry[i].turn_rate_rad_per_s);
  }
  for (size_t i = 0; i < d.ground_truth.size(); ++i) {
    EXPECT_EQ(r->ground_truth[i].x_m, d.ground_truth[i].x_m);
    // A quaternion keeps the heading modulo a turn.
    EXPECT_NEAR(
        std::remainder(r->ground_truth[i].theta_rad - d.ground_truth[i].theta_rad, 2 * M_PI), 0.0,
        1e-12);
  }
  // Without a ground-truth topic there is none; the only image and odometry topics are found.
  StatusOr<Dataset> bare = ReadRosbag(Path("a.bag"), {});
  ASSERT_TRUE(bare.ok()) << bare.status().message();
  EXPECT_TRUE(bare->ground_truth.empty());
  EXPECT_EQ(bare->images.size(), 40u);
  // LoadDataset knows a bag by its first bytes, whatever its name.
  fs::copy_file(Path("a.bag"), Path("renamed.dat"));
  StatusOr<DatasetFormat> format = DetectDatasetFormat(Path("renamed.dat"));
  ASSERT_TRUE(format.ok());
  EXPECT_EQ(*format, DatasetFormat::kRosBag);
}

TEST_F(RosbagTest, RawAndCompressedEncodingsDecodeToTheExpectedGrey) {
  {
    rosbag::Bag bag(Path("raw.bag"), rosbag::bagmode::Write);
    auto raw = [&](const std::string& encoding, int channels, std::vector<uint8_t> pixel,
                   bool big_endian, int second) {
      sensor_msgs::Image m;
      m.header.stamp = ros::Time(100 + second, 0);
      m.width = 3;
      m.height = 2;
      m.encoding = encoding;
      m.is_bigendian = big_endian;
      m.step = static_cast<uint32_t>(3 * pixel.size()) + 4;  // rows padded by 4 bytes
      for (int r = 0; r < 2; ++r) {
        for (int c = 0; c < 3; ++c) m.data.insert(m.data.end(), pixel.begin(), pixel.end());
        m.data.insert(m.data.end(), 4, 0xEE);
      }
      (void)channels;
      bag.write("/cam", m.header.stamp, m);
    };
    raw("mono8", 1, {200}, false, 0);
    raw("rgb8", 3, {255, 0, 0}, false, 1);          // pure red
    raw("bgr8", 3, {0, 0, 255}, false, 2);          // pure red too
    raw("mono16", 1, {0x12, 0x34}, true, 3);        // 0x1234 big-endian: high byte 0x12
    raw("16UC1", 1, {0x34, 0x12}, false, 4);        // 0x1234 little-endian
    raw("bgra8", 4, {255, 255, 255, 0}, false, 5);  // white
  }
  StatusOr<Dataset> d = ReadRosbag(Path("raw.bag"), {});
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_EQ(d->images.size(), 6u);
  EXPECT_EQ(d->images[5].time_s, 5.0);
  // OpenCV's grey of pure red: 0.299 * 255 = 76.2.
  const int expected[] = {200, 76, 76, 0x12, 0x12, 255};
  FileImageLoader loader;
  for (int i = 0; i < 6; ++i) {
    StatusOr<GrayImage> image = loader.Load(d->ImagePath(d->images[i]));
    ASSERT_TRUE(image.ok()) << image.status().message();
    ASSERT_EQ(image->width, 3);
    ASSERT_EQ(image->height, 2);
    for (uint8_t p : image->pixels) EXPECT_EQ(p, expected[i]) << "image " << i;
  }
  // A JPEG of a flat grey field decodes to that grey (to within the codec's rounding).
  {
    rosbag::Bag bag(Path("jpeg.bag"), rosbag::bagmode::Write);
    sensor_msgs::CompressedImage m;
    m.header.stamp = ros::Time(5, 0);
    m.format = "jpeg";
    const cv::Mat flat(24, 32, CV_8U, cv::Scalar(90));
    cv::imencode(".jpg", flat, m.data);
    bag.write("/stlucia/camera/image/compressed", m.header.stamp, m);
    m.data = {1, 2, 3};  // not an image
    m.header.stamp = ros::Time(6, 0);
    bag.write("/stlucia/camera/image/compressed", m.header.stamp, m);
  }
  d = ReadRosbag(Path("jpeg.bag"), {"/stlucia/camera/image", "", "", ""});
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_EQ(d->images.size(), 2u);
  StatusOr<GrayImage> jpeg = loader.Load(d->ImagePath(d->images[0]));
  ASSERT_TRUE(jpeg.ok()) << jpeg.status().message();
  for (uint8_t p : jpeg->pixels) EXPECT_NEAR(p, 90, 1);
  StatusOr<GrayImage> broken = loader.Load(d->ImagePath(d->images[1]));
  ASSERT_FALSE(broken.ok());
  EXPECT_NE(broken.status().message().find("jpeg.bag#1: cannot decode image (format 'jpeg')"),
            std::string::npos)
      << broken.status().message();
  // Encoded bytes come out as stored, with their extension.
  BagImageReader reader;
  StatusOr<EncodedImage> encoded = reader.Encoded(d->ImagePath(d->images[0]));
  ASSERT_TRUE(encoded.ok()) << encoded.status().message();
  EXPECT_EQ(encoded->extension, "jpg");
  EXPECT_EQ(encoded->bytes[0], 0xFF);
}

TEST_F(RosbagTest, TopicsAreChosenOrTheErrorSaysWhichToChoose) {
  {
    rosbag::Bag bag(Path("two.bag"), rosbag::bagmode::Write);
    sensor_msgs::CompressedImage m;
    m.header.stamp = ros::Time(1, 0);
    m.format = "png";
    bag.write("/irat_red/camera/image/compressed", m.header.stamp, m);
    bag.write("/overhead/camera/image/compressed", m.header.stamp, m);
    nav_msgs::Odometry o;
    o.header.stamp = ros::Time(1, 0);
    bag.write("/irat_red/odom", o.header.stamp, o);
  }
  std::string e = ReadError(Path("two.bag"));
  EXPECT_NE(e.find("2 image topics (/irat_red/camera/image/compressed, "
                   "/overhead/camera/image/compressed): choose one with [bag] image_topic"),
            std::string::npos)
      << e;
  StatusOr<Dataset> d = ReadRosbag(Path("two.bag"), {"/irat_red/camera/image", "", "", ""});
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_EQ(d->images.size(), 1u);
  EXPECT_EQ(d->odometry.size(), 1u);
  e = ReadError(Path("two.bag"), {"/irat_red/camera/image", "/irat_red/odometry", "", ""});
  EXPECT_NE(e.find("no topic /irat_red/odometry ([bag] odometry_topic); the bag has "
                   "/irat_red/camera/image/compressed (sensor_msgs/CompressedImage)"),
            std::string::npos)
      << e;
  e = ReadError(Path("two.bag"), {"/irat_red/odom", "", "", ""});
  EXPECT_NE(e.find("topic /irat_red/odom ([bag] image_topic) carries nav_msgs/Odometry, not "
                   "image messages"),
            std::string::npos)
      << e;
  BagTopics bad{"/cam era", "", "", ""};
  std::string why;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("image_topic '/cam era'"), std::string::npos) << why;
}

TEST_F(RosbagTest, StampsGoingBackwardsAndNonFiniteValuesAreErrorsNamingTheMessage) {
  {
    rosbag::Bag bag(Path("back.bag"), rosbag::bagmode::Write);
    nav_msgs::Odometry o;
    for (int i : {0, 1, 2}) {
      o.header.stamp = ros::Time(10 + (i == 2 ? 0 : i), 500);  // the third goes back 1 s
      bag.write("/odom", ros::Time(10 + i, 0), o);
    }
  }
  std::string e = ReadError(Path("back.bag"));
  EXPECT_NE(e.find("back.bag: message 2 on /odom: header stamp goes backwards "
                   "(10.000000500 s after 11.000000500 s"),
            std::string::npos)
      << e;
  {
    rosbag::Bag bag(Path("nan.bag"), rosbag::bagmode::Write);
    nav_msgs::Odometry o;
    o.header.stamp = ros::Time(3, 0);
    bag.write("/odom", o.header.stamp, o);
    o.header.stamp = ros::Time(4, 0);
    o.twist.twist.angular.z = std::numeric_limits<double>::quiet_NaN();
    bag.write("/odom", o.header.stamp, o);
  }
  e = ReadError(Path("nan.bag"));
  EXPECT_NE(e.find("message 1 on /odom: twist.twist.angular.z is not a finite number"),
            std::string::npos)
      << e;
  // A zero header stamp (unset) falls back to the record time.
  {
    rosbag::Bag bag(Path("zero.bag"), rosbag::bagmode::Write);
    nav_msgs::Odometry o;
    bag.write("/odom", ros::Time(7, 0), o);
    bag.write("/odom", ros::Time(9, 250000000), o);
  }
  StatusOr<Dataset> d = ReadRosbag(Path("zero.bag"), {});
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_EQ(d->odometry.size(), 2u);
  EXPECT_EQ(d->odometry[1].time_s, 2.25);
}

TEST_F(RosbagTest, TruncatedAndCorruptedBagsAreErrorsNotPartialDataSets) {
  IndexedImages images;
  ASSERT_TRUE(
      WriteRosbag(Sample(30), &images, {"/c/image", "/c/odom", "", ""}, Path("a.bag")).ok());
  std::ifstream in(Path("a.bag"), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 1000u);
  for (size_t keep : {bytes.size() / 2, bytes.size() - 10, size_t{20}}) {
    std::ofstream(Path("cut.bag"), std::ios::binary) << bytes.substr(0, keep);
    const std::string e = ReadError(Path("cut.bag"));
    EXPECT_NE(e.find("cut.bag: not a well-formed ROS bag at byte "), std::string::npos)
        << keep << ": " << e;
  }
  // The bag header record's length field (right after the 13-byte magic) made huge.
  std::string corrupt = bytes;
  for (int i = 13; i < 17; ++i) corrupt[static_cast<size_t>(i)] = '\xff';
  std::ofstream(Path("bad.bag"), std::ios::binary) << corrupt;
  std::string e = ReadError(Path("bad.bag"));
  EXPECT_NE(e.find("bad.bag: not a well-formed ROS bag at byte 13: a record header of "
                   "4294967295 bytes"),
            std::string::npos)
      << e;
  // A header field longer than its header: what overflows librosbag's own header parser (found
  // by rosbag_fuzzer); the structure check refuses it before librosbag reads the file.
  corrupt = bytes;
  const size_t field = corrupt.find("index_pos=") - 4;
  corrupt[field] = '\xec';
  std::ofstream(Path("long.bag"), std::ios::binary) << corrupt;
  e = ReadError(Path("long.bag"));
  EXPECT_NE(e.find("a header field longer than its header"), std::string::npos) << e;
  // A message whose image data claims 4 GB in a 20 kB bag: librosbag resized the vector to the
  // claimed length before finding the bytes missing (rosbag_fuzzer: out of memory). The layout
  // of each message is checked first now.
  e = ReadError(std::string(ratslam::test_paths::SourceDir()) +
                    "/fuzz/regressions/rosbag_fuzzer/oom-image-data-length-4gb",
                {"", "", "/r/pose", ""});
  EXPECT_NE(e.find("sensor_msgs/CompressedImage on /r/camera/image/compressed holds a field "
                   "longer than the message"),
            std::string::npos)
      << e;
  // An unindexed bag (a recording that was killed) says how to repair it.
  corrupt = bytes;
  const size_t index_pos = corrupt.find("index_pos=") + 10;
  for (size_t i = 0; i < 8; ++i) corrupt[index_pos + i] = '\0';
  std::ofstream(Path("unindexed.bag"), std::ios::binary) << corrupt;
  e = ReadError(Path("unindexed.bag"));
  EXPECT_NE(e.find("run `rosbag reindex`"), std::string::npos) << e;
  // An index_pos that points into the middle of a record.
  corrupt = bytes;
  corrupt[index_pos] = static_cast<char>(corrupt[index_pos] + 1);
  std::ofstream(Path("offset.bag"), std::ios::binary) << corrupt;
  e = ReadError(Path("offset.bag"));
  EXPECT_NE(e.find("not a well-formed ROS bag"), std::string::npos) << e;
  std::ofstream(Path("text.bag")) << "time_s,x\n1,2\n";
  e = ReadError(Path("text.bag"));
  EXPECT_NE(e.find("text.bag: not a ROS 1 bag (it does not start with #ROSBAG V2.0)"),
            std::string::npos)
      << e;
  // An image reference past the bag's end, or into a bag that is gone.
  FileImageLoader loader;
  StatusOr<GrayImage> past = loader.Load(Path("a.bag") + "#999");
  ASSERT_FALSE(past.ok());
  EXPECT_NE(past.status().message().find("a.bag#999: the bag has 60 messages"), std::string::npos)
      << past.status().message();
  StatusOr<GrayImage> odometry = loader.Load(Path("a.bag") + "#1");
  ASSERT_FALSE(odometry.ok());
  EXPECT_NE(odometry.status().message().find("is a nav_msgs/Odometry, not an image"),
            std::string::npos)
      << odometry.status().message();
}

// Compressed chunks (bz2 and lz4, as `rosbag record --bz2/--lz4` writes them) pass the structure
// check, which decompresses them to check the records inside, and read back.
TEST_F(RosbagTest, CompressedBagsReadBack) {
  for (auto compression : {rosbag::compression::BZ2, rosbag::compression::LZ4}) {
    {
      rosbag::Bag bag(Path("c.bag"), rosbag::bagmode::Write);
      bag.setCompression(compression);
      bag.setChunkThreshold(2000);  // several chunks
      for (int i = 0; i < 50; ++i) {
        nav_msgs::Odometry o;
        o.header.stamp = ros::Time(100 + i, 0);
        o.twist.twist.linear.x = 0.25 * i;
        bag.write("/odom", o.header.stamp, o);
      }
    }
    StatusOr<Dataset> d = ReadRosbag(Path("c.bag"), {});
    ASSERT_TRUE(d.ok()) << d.status().message();
    ASSERT_EQ(d->odometry.size(), 50u);
    EXPECT_EQ(d->odometry[49].forward_speed_m_per_s, 0.25 * 49);
    EXPECT_EQ(d->odometry[49].time_s, 49.0);
    fs::remove(Path("c.bag"));
  }
}

TEST_F(RosbagTest, WriterRefusesWhatABagCannotHold) {
  IndexedImages images;
  Dataset d = Sample(3);
  d.wifi.push_back({0.5, {{"aa:bb", -50}}});
  Status s = WriteRosbag(d, &images, {"/c", "/o", "", ""}, Path("w.bag"));
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("Wi-Fi scans, compass and barometer readings are not written"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(Path("w.bag")));
  s = WriteRosbag(Sample(3), &images, {"", "/o", "", ""}, Path("w.bag"));
  EXPECT_FALSE(s.ok());
}

TEST(BagImageReference, SplitsAtTheLastHashAfterDotBag) {
  std::string bag;
  uint64_t n = 0;
  ASSERT_TRUE(ParseBagImageReference("/data/a#b/run.bag#1234", &bag, &n));
  EXPECT_EQ(bag, "/data/a#b/run.bag");
  EXPECT_EQ(n, 1234u);
  EXPECT_FALSE(ParseBagImageReference("/data/run.bag", &bag, &n));
  EXPECT_FALSE(ParseBagImageReference("/data/run.png#3", &bag, &n));
  EXPECT_FALSE(ParseBagImageReference("/data/run.bag#", &bag, &n));
  EXPECT_FALSE(ParseBagImageReference("/data/run.bag#-1", &bag, &n));
}

}  // namespace
}  // namespace ratslam::dataset
