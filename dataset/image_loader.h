// Loads grey images from files, ROS bags and videos for the camera front ends (the interface and
// the image type: common/gray_image.h).
#ifndef RATSLAM_DATASET_IMAGE_LOADER_H_
#define RATSLAM_DATASET_IMAGE_LOADER_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/gray_image.h"
#include "common/status.h"

namespace ratslam::dataset {

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

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_IMAGE_LOADER_H_
