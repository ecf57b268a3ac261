// A grey image and the interface that loads one: the value every camera layer shares (front
// ends, renderer, simulator), at the bottom so that none of them needs the data-set readers.
// dataset/image_loader.h has the loader that reads files, bags and videos.
#ifndef RATSLAM_COMMON_GRAY_IMAGE_H_
#define RATSLAM_COMMON_GRAY_IMAGE_H_

#include <cstdint>
#include <string>
#include <vector>

#include "common/status.h"

namespace ratslam {

struct GrayImage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> pixels;  // rows top to bottom, no padding
};

// Behind an interface so that tests can feed images from memory and replays can read them from
// disk.
class ImageLoader {
 public:
  virtual ~ImageLoader() = default;
  virtual StatusOr<GrayImage> Load(const std::string& path) = 0;
};

}  // namespace ratslam

#endif  // RATSLAM_COMMON_GRAY_IMAGE_H_
