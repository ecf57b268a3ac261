// ROS 2 bags as MCAP files: any bytes are read into a data set or an error naming the file, and
// every image of an accepted file decodes or fails with a message.
#include "dataset/rosbag2.h"
#include "fuzz/fuzz_support.h"
#include "fuzz/ros2_seeds.h"

namespace ratslam::fuzz {

std::vector<std::string> FuzzSeeds() { return {Ros2SeedMcap()}; }

}  // namespace ratslam::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ratslam;
  const std::string path = fuzz::WriteScratchFile("input.mcap", data, size);
  for (const char* images : {"/camera/image_raw", "/camera/image/compressed"}) {
    dataset::BagTopics topics;
    topics.image_topic = images;
    topics.ground_truth_topic = "/pose";
    topics.imu_topic = "/imu";
    StatusOr<dataset::Dataset> d = dataset::ReadRos2Bag(path, topics);
    if (!d.ok()) {
      if (d.status().message().find("input.mcap") == std::string::npos) __builtin_trap();
      continue;
    }
    dataset::FileImageLoader loader;  // a fresh one: the file changes between inputs
    for (size_t i = 0; i < d->images.size() && i < 20; ++i) {
      StatusOr<GrayImage> image = loader.Load(d->ImagePath(d->images[i]));
      if (image.ok() && image->pixels.size() != static_cast<size_t>(image->width) *
                                                    static_cast<size_t>(image->height)) {
        __builtin_trap();
      }
    }
  }
  return 0;
}
