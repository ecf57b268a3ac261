// An RGBA image in memory, rows top to bottom, and PNG input and output.
#ifndef RATSLAM_RENDER_IMAGE_H_
#define RATSLAM_RENDER_IMAGE_H_

#include <cstdint>
#include <string>
#include <vector>

#include "common/status.h"
#include "render/scene.h"

namespace ratslam::render {

struct RgbaImage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> pixels;  // width * height * 4, rows top to bottom

  Rgba At(int x, int y) const {
    const uint8_t* p = &pixels[(static_cast<size_t>(y) * width + x) * 4];
    return {p[0], p[1], p[2], p[3]};
  }
};

// An opaque image is written as RGB, others as RGBA; the bytes depend only on the image (not on
// the number of cores that compress it). Written to a temporary file and renamed into place.
Status WritePng(const RgbaImage& image, const std::string& path);
StatusOr<RgbaImage> ReadPng(const std::string& path);

// Width in pixels of `text` drawn at `height_px` by DrawTexts.
float TextWidthPx(const std::string& text, float height_px);

// Draws the scene's texts onto `image` (Hershey fonts, antialiased).
void DrawTexts(const Scene& scene, RgbaImage* image);

}  // namespace ratslam::render

#endif  // RATSLAM_RENDER_IMAGE_H_
