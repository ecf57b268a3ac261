// ROS 2 CDR messages: any bytes decode as each message type or fail with an error naming the
// field; a decoded image holds no more bytes than the input.
#include "dataset/ros2_messages.h"
#include "fuzz/fuzz_support.h"
#include "fuzz/ros2_seeds.h"

namespace ratslam::fuzz {

std::vector<std::string> FuzzSeeds() {
  std::vector<std::string> seeds;
  for (const std::string& m : Ros2SeedMessages()) seeds.push_back(m);
  return seeds;
}

}  // namespace ratslam::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ratslam;
  const std::string where = "input";
  auto named = [&](const Status& s) {
    if (s.message().rfind(where + ": ", 0) != 0) __builtin_trap();
  };
  if (auto m = dataset::DecodeRos2Stamp(data, size, where); !m.ok()) named(m.status());
  if (auto m = dataset::DecodeRos2Image(data, size, where); !m.ok()) {
    named(m.status());
  } else if (m->data.size() > size) {
    __builtin_trap();
  }
  if (auto m = dataset::DecodeRos2CompressedImage(data, size, where); !m.ok()) {
    named(m.status());
  } else if (m->data.size() > size) {
    __builtin_trap();
  }
  if (auto m = dataset::DecodeRos2Odometry(data, size, where); !m.ok()) named(m.status());
  if (auto m = dataset::DecodeRos2PoseStamped(data, size, where); !m.ok()) named(m.status());
  if (auto m = dataset::DecodeRos2Imu(data, size, where); !m.ok()) named(m.status());
  return 0;
}
