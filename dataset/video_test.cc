#include "dataset/video.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/videoio.hpp>

#include "dataset/dataset_loader.h"

namespace ratslam::dataset {
namespace {
namespace fs = std::filesystem;

class VideoTest : public ::testing::Test {
 protected:
  static constexpr int kFrames = 12, kWidth = 64, kHeight = 48;
  void SetUp() override {
    folder_ = fs::temp_directory_path() /
              ("ratslam_video_test_" + std::to_string(::getpid()) + "_" +
               ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(folder_);
    fs::create_directories(folder_);
    // Motion JPEG at the best quality, with OpenCV's own AVI writer (no codec library needed).
    cv::VideoWriter writer(Path("log_irat.avi"), cv::CAP_OPENCV_MJPEG,
                           cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 5.0,
                           cv::Size(kWidth, kHeight), true);
    ASSERT_TRUE(writer.isOpened());
    writer.set(cv::VIDEOWRITER_PROP_QUALITY, 100);
    for (int n = 0; n < kFrames; ++n) writer.write(Frame(n));
  }
  void TearDown() override { fs::remove_all(folder_); }
  std::string Path(const std::string& name) const { return (folder_ / name).string(); }
  // Flat grey blocks whose level encodes the frame: JPEG keeps flat blocks nearly exact.
  static cv::Mat Frame(int n) {
    const int v = 20 + 15 * n;
    return cv::Mat(kHeight, kWidth, CV_8UC3, cv::Scalar(v, v, v));
  }
  void WriteLog(int rows, const std::string& extra = "") {
    std::ofstream log(Path("log_irat.txt"));
    log << "sec,nsec,trans_vel,rot_vel,frame\n";
    for (int n = 0; n < rows; ++n) {
      log << 1322000000 + n / 4 << "," << (n % 4) * 250000000 << "," << 0.1 * n << "," << -0.01 * n
          << "," << n << "\n";
    }
    log << extra;
  }
  fs::path folder_;
};

TEST_F(VideoTest, FramesTakeTheOdometryLogsTimesAndDecodeInAnyOrder) {
  WriteLog(kFrames + 3);  // rows beyond the last frame are not used
  StatusOr<Dataset> d = LoadDataset(Path("log_irat.avi"), {});
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_EQ(d->images.size(), size_t{kFrames});
  ASSERT_EQ(d->odometry.size(), size_t{kFrames});
  EXPECT_EQ(d->name, "log_irat");
  for (int n = 0; n < kFrames; ++n) {
    EXPECT_NEAR(d->images[n].time_s, 0.25 * n, 1e-9);
    EXPECT_EQ(d->odometry[n].time_s, d->images[n].time_s);
  }
  // The first row is the time reference only; later rows carry their velocities.
  EXPECT_EQ(d->odometry[0].forward_speed_m_per_s, 0.0);
  EXPECT_NEAR(d->odometry[5].forward_speed_m_per_s, 0.5, 1e-12);
  EXPECT_NEAR(d->odometry[5].turn_rate_rad_per_s, -0.05, 1e-12);
  FileImageLoader loader;
  for (int n : {0, 1, 2, 7, 3, 11, 0}) {  // in order, then jumps both ways
    StatusOr<GrayImage> image = loader.Load(d->ImagePath(d->images[n]));
    ASSERT_TRUE(image.ok()) << image.status().message();
    ASSERT_EQ(image->width, kWidth);
    ASSERT_EQ(image->height, kHeight);
    for (uint8_t p : image->pixels) ASSERT_NEAR(p, 20 + 15 * n, 2) << "frame " << n;
  }
  EXPECT_FALSE(loader.Load(Path("log_irat.avi") + "#" + std::to_string(kFrames)).ok());
}

TEST_F(VideoTest, WithoutALogFramesFollowTheFrameRate) {
  StatusOr<Dataset> d = ReadVideo(Path("log_irat.avi"), {});
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_EQ(d->images.size(), size_t{kFrames});
  EXPECT_TRUE(d->odometry.empty());
  EXPECT_NEAR(d->images[3].time_s, 3 / 5.0, 1e-9);  // the container's 5 frames per second
  VideoOptions options;
  options.frame_rate_hz = 20;
  d = ReadVideo(Path("log_irat.avi"), options);
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_NEAR(d->images[3].time_s, 3 / 20.0, 1e-12);
}

// Reading a video silences OpenCV only while it opens the file: the program's own OpenCV log
// level is left as it was, after a good file and after one OpenCV cannot open.
TEST_F(VideoTest, OpenCvLogLevelIsRestored) {
  namespace logging = cv::utils::logging;
  const logging::LogLevel before = logging::setLogLevel(logging::LOG_LEVEL_INFO);
  ASSERT_TRUE(ReadVideo(Path("log_irat.avi"), {}).ok());
  EXPECT_EQ(logging::getLogLevel(), logging::LOG_LEVEL_INFO);
  std::ofstream(Path("not_a_video.avi")) << "not a video";
  EXPECT_FALSE(ReadVideo(Path("not_a_video.avi"), {}).ok());
  EXPECT_EQ(logging::getLogLevel(), logging::LOG_LEVEL_INFO);
  logging::setLogLevel(before);
}

TEST_F(VideoTest, BadLogsAndFilesAreErrorsNamingFileLineAndColumn) {
  auto error = [&] {
    StatusOr<Dataset> d = ReadVideo(Path("log_irat.avi"), {});
    EXPECT_FALSE(d.ok());
    return d.ok() ? "" : d.status().message();
  };
  WriteLog(kFrames - 2);
  EXPECT_NE(error().find("log_irat.txt: 10 rows for the 12 frames"), std::string::npos) << error();
  WriteLog(4, "1322000001,0,nan,0\n");
  EXPECT_NE(error().find("log_irat.txt:6: column 'trans_vel': not a finite number: 'nan'"),
            std::string::npos)
      << error();
  WriteLog(4, "1321000000,0,0,0\n");
  EXPECT_NE(error().find("log_irat.txt:6: time goes backwards"), std::string::npos) << error();
  WriteLog(2, "1322000001,5\n");
  EXPECT_NE(error().find("log_irat.txt:4: expected sec, nsec, trans_vel, rot_vel; found 2"),
            std::string::npos)
      << error();
  std::ofstream(Path("fake.mp4")) << "not a video";
  StatusOr<Dataset> fake = ReadVideo(Path("fake.mp4"), {});
  ASSERT_FALSE(fake.ok());
  EXPECT_NE(fake.status().message().find("fake.mp4: OpenCV's video reader cannot open it"),
            std::string::npos)
      << fake.status().message();
}

}  // namespace
}  // namespace ratslam::dataset
