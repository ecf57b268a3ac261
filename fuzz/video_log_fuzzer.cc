// Videos with OpenRatSLAM odometry logs: any log is read into a data set or an error naming the
// log; an accepted one pairs every frame with a row, in time order.
#include <fstream>
#include <string>

#include "dataset/video.h"
#include "fuzz/fuzz_support.h"

namespace ratslam::fuzz {

namespace {
class Flat : public ImageLoader {
 public:
  StatusOr<GrayImage> Load(const std::string&) override {
    GrayImage image;
    image.width = 16;
    image.height = 8;
    image.pixels.assign(128, 90);
    return image;
  }
};

// A four-frame video written once per process; the log beside it is the fuzzed input.
const std::string& Video() {
  static const std::string path = [] {
    const std::string p = (Scratch().path() / "log_fuzz.avi").string();
    dataset::Dataset d;
    for (int i = 0; i < 4; ++i) d.images.push_back({0.1 * i, "x", i});
    Flat images;
    (void)dataset::WriteVideo(d, &images, p, 10.0);
    return p;
  }();
  return path;
}
}  // namespace

std::vector<std::string> FuzzSeeds() {
  return {
      "sec,nsec,trans_vel,rot_vel\n1322000000,0,0.1,0.0\n1322000000,100000000,0.2,-0.1\n"
      "1322000000,200000000,0.2,0.1\n1322000000,300000000,0.3,0.0,extra\n",
      "sec nsec trans rot\n5 0 1 2\n5 1 1 2\n6 0 1e3 -2\n7 999999999 0 0\n8 0 0 0\n"};
}

}  // namespace ratslam::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ratslam;
  const std::string& video = fuzz::Video();
  const std::string log = fuzz::WriteScratchFile("log.txt", data, size);
  dataset::VideoOptions options;
  options.odometry_log = log;
  StatusOr<dataset::Dataset> d = dataset::ReadVideo(video, options);
  if (!d.ok()) {
    const std::string& m = d.status().message();
    if (m.find("log.txt") == std::string::npos && m.find("log_fuzz.avi") == std::string::npos) {
      __builtin_trap();
    }
    return 0;
  }
  if (d->images.size() != d->odometry.size()) __builtin_trap();
  for (size_t i = 1; i < d->images.size(); ++i) {
    if (!(d->images[i].time_s >= d->images[i - 1].time_s)) __builtin_trap();
  }
  return 0;
}
