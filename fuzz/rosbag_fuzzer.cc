// ROS 1 bags: any bytes are read through librosbag-storage into a data set or an error naming
// the bag, and every image of an accepted bag decodes or fails with a message.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "dataset/rosbag.h"
#include "fuzz/fuzz_support.h"

namespace ratslam::fuzz {

namespace {
// A small image of a flat grey field and a gradient, `n` frames with odometry.
class Pattern : public ImageLoader {
 public:
  StatusOr<GrayImage> Load(const std::string& path) override {
    GrayImage image;
    image.width = 6;
    image.height = 4;
    for (int i = 0; i < 24; ++i) image.pixels.push_back(static_cast<uint8_t>(path.size() * i));
    return image;
  }
};
}  // namespace

std::vector<std::string> FuzzSeeds() {
  if (!dataset::RosbagSupported()) return {"#ROSBAG V2.0\n"};
  dataset::Dataset d;
  for (int i = 0; i < 3; ++i) {
    d.images.push_back({0.5 * i, std::string(static_cast<size_t>(i + 1), 'x'), i});
    d.odometry.push_back({0.5 * i + 0.1, 0.4, 0.1});
    d.ground_truth.push_back({0.5 * i, 1.0 * i, 0.0, 0.0, 0});
  }
  Pattern images;
  const std::string path = (Scratch().path() / "seed.bag").string();
  if (!dataset::WriteRosbag(d, &images, {"/r/camera/image/compressed", "/r/odom", "/r/pose", ""},
                            path)
           .ok()) {
    return {"#ROSBAG V2.0\n"};
  }
  std::ifstream in(path, std::ios::binary);
  return {std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>())};
}

}  // namespace ratslam::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ratslam;
  const std::string path = fuzz::WriteScratchFile("input.bag", data, size);
  StatusOr<dataset::Dataset> d = dataset::ReadRosbag(path, {"", "", "/r/pose", ""});
  if (!d.ok()) {
    if (d.status().message().find("input.bag") == std::string::npos) __builtin_trap();
    return 0;
  }
  dataset::FileImageLoader loader;  // a fresh one: the file changes between inputs
  for (size_t i = 0; i < d->images.size() && i < 20; ++i) {
    StatusOr<GrayImage> image = loader.Load(d->ImagePath(d->images[i]));
    if (image.ok() && image->pixels.size() !=
                          static_cast<size_t>(image->width) * static_cast<size_t>(image->height)) {
      __builtin_trap();
    }
  }
  return 0;
}
