// Internal to the bag readers (ROS 1 and ROS 2): sensor_msgs Image and CompressedImage contents,
// whatever container they came from, as grey images or as encoded files.
#ifndef RATSLAM_DATASET_ROS_IMAGE_H_
#define RATSLAM_DATASET_ROS_IMAGE_H_

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "common/status.h"
#include "dataset/image_loader.h"
#include "dataset/rosbag.h"

namespace ratslam::dataset {

// A sensor_msgs Image's fields (the same in ROS 1 and ROS 2); `data` is not owned.
struct RawImageView {
  uint32_t height = 0;
  uint32_t width = 0;
  std::string_view encoding;
  bool big_endian = false;
  uint32_t step = 0;  // bytes per row
  const uint8_t* data = nullptr;
  size_t size = 0;
};

// mono8, mono16 (its high byte), bgr8, rgb8, bgra8, rgba8 and their 8UC1/3/4 names, to grey.
// Errors name `where` and the field that does not fit (encoding, size, step).
StatusOr<GrayImage> GrayFromRawImage(const RawImageView& image, const std::string& where);

// A CompressedImage's data (PNG, JPEG, whatever OpenCV reads) to grey.
StatusOr<GrayImage> GrayFromCompressedImage(const uint8_t* data, size_t size,
                                            std::string_view format, const std::string& where);

// "png" or "jpg" from the data's signature, else from `format`; empty when neither says.
std::string CompressedImageExtension(const uint8_t* data, size_t size, std::string_view format);

// A raw image as a lossless grey PNG.
StatusOr<EncodedImage> PngFromRawImage(const RawImageView& image, const std::string& where);

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_ROS_IMAGE_H_
