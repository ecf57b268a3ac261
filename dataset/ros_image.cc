#include "dataset/ros_image.h"

#include <algorithm>
#include <cctype>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "dataset/opencv_gray.h"

namespace ratslam::dataset {
namespace {

// The raw image as an OpenCV matrix in BGR(A) or grey, after checking its size fields.
StatusOr<cv::Mat> RawToMat(const RawImageView& msg, const std::string& where) {
  const std::string_view enc = msg.encoding;
  int channels = 0, depth_bytes = 1;
  if (enc == "mono8" || enc == "8UC1") {
    channels = 1;
  } else if (enc == "mono16" || enc == "16UC1") {
    channels = 1;
    depth_bytes = 2;
  } else if (enc == "bgr8" || enc == "rgb8" || enc == "8UC3") {
    channels = 3;
  } else if (enc == "bgra8" || enc == "rgba8" || enc == "8UC4") {
    channels = 4;
  } else {
    return Status::Error(where + ": image encoding '" + std::string(enc) +
                         "' is not read (mono8, mono16, bgr8, rgb8, bgra8, rgba8)");
  }
  const uint64_t row_bytes = uint64_t{msg.width} * static_cast<uint64_t>(channels * depth_bytes);
  if (msg.width == 0 || msg.height == 0 || msg.width > 65535 || msg.height > 65535) {
    return Status::Error(where + ": image size " + std::to_string(msg.width) + "x" +
                         std::to_string(msg.height) + " out of range");
  }
  if (msg.step < row_bytes || uint64_t{msg.step} * msg.height > msg.size) {
    return Status::Error(where + ": image step " + std::to_string(msg.step) + " and height " +
                         std::to_string(msg.height) + " do not fit its " +
                         std::to_string(msg.size) + " bytes of data");
  }
  const int w = static_cast<int>(msg.width), h = static_cast<int>(msg.height);
  cv::Mat mat(h, w, CV_8UC(channels));
  for (int r = 0; r < h; ++r) {
    const uint8_t* src = msg.data + static_cast<size_t>(r) * msg.step;
    uint8_t* dst = mat.ptr<uint8_t>(r);
    if (depth_bytes == 1) {
      std::copy(src, src + static_cast<size_t>(w) * channels, dst);
    } else {
      for (int c = 0; c < w; ++c) {  // the high byte of each 16-bit value
        dst[c] = msg.big_endian ? src[2 * c] : src[2 * c + 1];
      }
    }
  }
  if (enc == "rgb8") cv::cvtColor(mat, mat, cv::COLOR_RGB2BGR);
  if (enc == "rgba8") cv::cvtColor(mat, mat, cv::COLOR_RGBA2BGRA);
  return mat;
}

}  // namespace

StatusOr<GrayImage> GrayFromRawImage(const RawImageView& image, const std::string& where) {
  StatusOr<cv::Mat> mat = RawToMat(image, where);
  if (!mat.ok()) return mat.status();
  return GrayFromMat(*mat, where);
}

StatusOr<GrayImage> GrayFromCompressedImage(const uint8_t* data, size_t size,
                                            std::string_view format, const std::string& where) {
  if (size == 0) return Status::Error(where + ": empty compressed image");
  if (size > 0x7fffffff) return Status::Error(where + ": compressed image over 2 GiB");
  cv::Mat mat;
  try {
    const cv::Mat raw(1, static_cast<int>(size), CV_8U, const_cast<uint8_t*>(data));
    mat = cv::imdecode(raw, cv::IMREAD_GRAYSCALE);
  } catch (const cv::Exception& e) {
    return Status::Error(where + ": cannot decode image (format '" + std::string(format) +
                         "'): " + e.what());
  }
  if (mat.empty()) {
    return Status::Error(where + ": cannot decode image (format '" + std::string(format) + "')");
  }
  return GrayFromMat(mat, where);
}

std::string CompressedImageExtension(const uint8_t* d, size_t size, std::string_view format) {
  if (size >= 8 && d[0] == 0x89 && d[1] == 'P' && d[2] == 'N' && d[3] == 'G') return "png";
  if (size >= 3 && d[0] == 0xFF && d[1] == 0xD8 && d[2] == 0xFF) return "jpg";
  std::string lower;
  for (char c : format) lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (lower.find("png") != std::string::npos) return "png";
  if (lower.find("jpeg") != std::string::npos || lower.find("jpg") != std::string::npos) {
    return "jpg";
  }
  return "";
}

StatusOr<EncodedImage> PngFromRawImage(const RawImageView& image, const std::string& where) {
  StatusOr<GrayImage> grey = GrayFromRawImage(image, where);
  if (!grey.ok()) return grey.status();
  const cv::Mat g(grey->height, grey->width, CV_8U, grey->pixels.data());
  EncodedImage out;
  out.extension = "png";
  if (!cv::imencode(".png", g, out.bytes)) return Status::Error(where + ": cannot encode PNG");
  return out;
}

}  // namespace ratslam::dataset
