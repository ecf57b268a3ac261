#include "viewer/animation.h"

#include <cstdio>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

namespace ratslam::viewer {

struct AnimationWriter::Video {
  cv::VideoWriter writer;
  bool failed = false;
};

AnimationWriter::AnimationWriter(std::string folder, double fps)
    : folder_(std::move(folder)), fps_(fps), video_(std::make_unique<Video>()) {}

AnimationWriter::~AnimationWriter() { Close(); }

Status AnimationWriter::AddFrame(const render::RgbaImage& frame) {
  if (frames_ == 0) {
    std::error_code ec;
    std::filesystem::create_directories(folder_, ec);
    if (ec) return Status::Error(folder_ + ": cannot create: " + ec.message());
  }
  char name[32];
  std::snprintf(name, sizeof name, "frame_%06d.png", frames_);
  RATSLAM_RETURN_IF_ERROR(
      render::WritePng(frame, (std::filesystem::path(folder_) / name).string()));
  if (!video_->failed) {
    cv::Mat rgba(frame.height, frame.width, CV_8UC4, const_cast<uint8_t*>(frame.pixels.data()));
    cv::Mat bgr;
    cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
    if (!video_->writer.isOpened() && frames_ == 0) {
      // OpenCV's own AVI container with MJPEG needs no external codec library.
      const std::string path = (std::filesystem::path(folder_) / "animation.avi").string();
      try {
        video_->writer.open(path, cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'),
                            fps_, bgr.size());
      } catch (const cv::Exception&) {
      }
      video_->failed = !video_->writer.isOpened();
    }
    if (video_->writer.isOpened()) video_->writer.write(bgr);
  }
  ++frames_;
  return Status::Ok();
}

bool AnimationWriter::Close() {
  const bool wrote = video_ && video_->writer.isOpened() && frames_ > 0;
  if (video_ && video_->writer.isOpened()) video_->writer.release();
  return wrote;
}

}  // namespace ratslam::viewer
