// Internal to the data-set readers: an OpenCV image (grey, BGR or BGRA, 8 bits) as a GrayImage.
#ifndef RATSLAM_DATASET_OPENCV_GRAY_H_
#define RATSLAM_DATASET_OPENCV_GRAY_H_

#include <algorithm>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "dataset/image_loader.h"

namespace ratslam::dataset {

inline StatusOr<GrayImage> GrayFromMat(const cv::Mat& mat, const std::string& where) {
  if (mat.empty()) return Status::Error(where + ": cannot decode image");
  cv::Mat grey;
  if (mat.channels() == 1) {
    grey = mat;
  } else if (mat.channels() == 3) {
    cv::cvtColor(mat, grey, cv::COLOR_BGR2GRAY);
  } else if (mat.channels() == 4) {
    cv::cvtColor(mat, grey, cv::COLOR_BGRA2GRAY);
  } else {
    return Status::Error(where + ": " + std::to_string(mat.channels()) + " channels");
  }
  if (grey.depth() != CV_8U) return Status::Error(where + ": not 8 bits per channel");
  GrayImage image;
  image.width = grey.cols;
  image.height = grey.rows;
  image.pixels.resize(static_cast<size_t>(grey.cols) * static_cast<size_t>(grey.rows));
  for (int r = 0; r < grey.rows; ++r) {
    std::copy(grey.ptr<uint8_t>(r), grey.ptr<uint8_t>(r) + grey.cols,
              image.pixels.begin() + static_cast<ptrdiff_t>(r) * grey.cols);
  }
  return image;
}

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_OPENCV_GRAY_H_
