// Loads grey images for the camera front ends. Behind an interface so that tests can feed images
// from memory and replays can read them from disk.
#ifndef RATSLAM_DATASET_IMAGE_LOADER_H_
#define RATSLAM_DATASET_IMAGE_LOADER_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/status.h"

namespace ratslam {

struct GrayImage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> pixels;  // rows top to bottom, no padding
};

class ImageLoader {
 public:
  virtual ~ImageLoader() = default;
  virtual StatusOr<GrayImage> Load(const std::string& path) = 0;
};

class BagImageReader;
class Ros2ImageReader;
class VideoFrameReader;

// Reads any format OpenCV's imgcodecs reads (PNG, JPEG, PGM, ...) and converts it to grey; a path
// `<file>.bag#<n>` is message n of a ROS bag (dataset/rosbag.h), `<file>.mcap#<n>` or
// `<file>.db3#<n>` one of a ROS 2 bag (dataset/rosbag2.h), `<video>#<n>` frame n of a video
// (dataset/video.h).
class FileImageLoader : public ImageLoader {
 public:
  FileImageLoader();
  ~FileImageLoader() override;
  StatusOr<GrayImage> Load(const std::string& path) override;

 private:
  std::unique_ptr<BagImageReader> bags_;
  std::unique_ptr<Ros2ImageReader> ros2_bags_;
  std::unique_ptr<VideoFrameReader> videos_;
};

}  // namespace ratslam

#endif  // RATSLAM_DATASET_IMAGE_LOADER_H_
