#include "sensors/dataset/image_loader.h"

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

namespace ratslam {

StatusOr<GrayImage> FileImageLoader::Load(const std::string& path) {
  if (!std::filesystem::exists(path)) return Status::Error(path + ": image file missing");
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

}  // namespace ratslam
