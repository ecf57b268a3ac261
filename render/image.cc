#include "render/image.h"

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/file_util.h"

namespace ratslam {

Status WritePng(const RgbaImage& image, const std::string& path) {
  if (image.width <= 0 || image.height <= 0) return Status::Error(path + ": empty image");
  cv::Mat rgba(image.height, image.width, CV_8UC4, const_cast<uint8_t*>(image.pixels.data()));
  // An opaque image (all our figures) goes out as RGB: a quarter less to filter and compress.
  bool opaque = true;
  for (size_t i = 3; i < image.pixels.size() && opaque; i += 4) opaque = image.pixels[i] == 255;
  cv::Mat bgr;
  cv::cvtColor(rgba, bgr, opaque ? cv::COLOR_RGBA2BGR : cv::COLOR_RGBA2BGRA);
  // OpenCV's defaults (no parameters) are its fastest PNG settings: naming a compression level
  // turns on adaptive row filters and doubles the time (measured with BM_EncodePng).
  std::vector<uchar> png;
  try {
    if (!cv::imencode(".png", bgr, png)) return Status::Error(path + ": cannot encode PNG");
  } catch (const cv::Exception& e) {
    return Status::Error(path + ": cannot encode PNG: " + e.what());
  }
  // Written checked and renamed into place: a full disk is an error, never a 0-byte PNG.
  return WriteFileAtomically(path, std::string(png.begin(), png.end()), /*flush_to_disk=*/false);
}

StatusOr<RgbaImage> ReadPng(const std::string& path) {
  if (!std::filesystem::exists(path)) return Status::Error(path + ": file missing");
  cv::Mat bgra = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (bgra.empty()) return Status::Error(path + ": cannot read image");
  cv::Mat rgba;
  if (bgra.channels() == 4) {
    cv::cvtColor(bgra, rgba, cv::COLOR_BGRA2RGBA);
  } else if (bgra.channels() == 3) {
    cv::cvtColor(bgra, rgba, cv::COLOR_BGR2RGBA);
  } else {
    cv::cvtColor(bgra, rgba, cv::COLOR_GRAY2RGBA);
  }
  RgbaImage image;
  image.width = rgba.cols;
  image.height = rgba.rows;
  image.pixels.assign(rgba.data, rgba.data + rgba.total() * 4);
  return image;
}

namespace {
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
// FONT_HERSHEY_SIMPLEX is about 22 px high (cap height) at scale 1.
double FontScale(float height_px) { return height_px / 22.0; }
int FontThickness(float height_px) {
  return std::max(1, static_cast<int>(std::lround(height_px / 14.0)));
}
}  // namespace

float TextWidthPx(const std::string& text, float height_px) {
  int baseline = 0;
  return static_cast<float>(
      cv::getTextSize(text, kFont, FontScale(height_px), FontThickness(height_px), &baseline)
          .width);
}

void DrawTexts(const Scene& scene, RgbaImage* image) {
  cv::Mat canvas(image->height, image->width, CV_8UC4, image->pixels.data());
  for (const SceneText& t : scene.texts()) {
    const double scale = FontScale(t.height_px);
    const int thickness = FontThickness(t.height_px);
    int baseline = 0;
    const cv::Size size = cv::getTextSize(t.text, kFont, scale, thickness, &baseline);
    int x = static_cast<int>(std::lround(t.position.x));
    if (t.anchor == TextAnchor::kCenter) x -= size.width / 2;
    if (t.anchor == TextAnchor::kRight) x -= size.width;
    // Our buffer is RGBA, so the scalar is given in that order.
    cv::putText(canvas, t.text, {x, static_cast<int>(std::lround(t.position.y))}, kFont, scale,
                cv::Scalar(t.color.r, t.color.g, t.color.b, t.color.a), thickness, cv::LINE_AA);
  }
}

}  // namespace ratslam
