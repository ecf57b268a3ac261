#include "dataset/image_loader.h"

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "common/file_util.h"
#include "dataset/rosbag.h"
#include "dataset/rosbag2.h"
#include "dataset/video.h"

namespace ratslam::dataset {

FileImageLoader::FileImageLoader()
    : bags_(std::make_unique<BagImageReader>()),
      ros2_bags_(std::make_unique<Ros2ImageReader>()),
      videos_(std::make_unique<VideoFrameReader>()) {}
FileImageLoader::~FileImageLoader() = default;

StatusOr<GrayImage> FileImageLoader::Load(const std::string& path) {
  std::string bag;
  uint64_t message = 0;
  if (!PathExists(path)) {  // then maybe a bag's message or a video's frame
    if (ParseBagImageReference(path, &bag, &message)) return bags_->Load(path);
    if (ParseRos2ImageReference(path, &bag, &message)) return ros2_bags_->Load(path);
    if (ParseVideoFrameReference(path, &bag, &message)) return videos_->Load(path);
    return Status::Error(path + ": image file missing");
  }
  // OpenCV would open a FIFO and wait for a writer for ever.
  if (!IsRegularFile(path)) return Status::Error(path + ": image is not a regular file");
  cv::Mat mat;
  try {
    mat = cv::imread(path, cv::IMREAD_GRAYSCALE);
  } catch (const cv::Exception& e) {
    return Status::Error(path + ": cannot decode image: " + e.what());
  }
  if (mat.empty()) return Status::Error(path + ": cannot decode image");
  GrayImage image;
  image.width = mat.cols;
  image.height = mat.rows;
  image.pixels.resize(static_cast<size_t>(mat.cols) * mat.rows);
  for (int r = 0; r < mat.rows; ++r) {
    std::copy(mat.ptr<uint8_t>(r), mat.ptr<uint8_t>(r) + mat.cols,
              image.pixels.begin() + static_cast<ptrdiff_t>(r) * mat.cols);
  }
  return image;
}

}  // namespace ratslam::dataset
