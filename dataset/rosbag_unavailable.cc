// A build without librosbag-storage-dev: every bag operation says how to get it.
#include "dataset/rosbag.h"

namespace ratslam::dataset {
namespace {
Status Unavailable(const std::string& what) {
  return Status::Error(what +
                       ": this build cannot read ROS bags: install librosbag-storage-dev, "
                       "libsensor-msgs-dev and libnav-msgs-dev (bash scripts/setup.sh does) "
                       "and rebuild, or convert the bag elsewhere");
}
}  // namespace

bool RosbagSupported() { return false; }

StatusOr<Dataset> ReadRosbag(const std::string& path, const BagTopics&) {
  return Unavailable(path);
}

class BagImageReader::Impl {};
BagImageReader::BagImageReader() = default;
BagImageReader::~BagImageReader() = default;
StatusOr<GrayImage> BagImageReader::Load(const std::string& reference) {
  return Unavailable(reference);
}
StatusOr<EncodedImage> BagImageReader::Encoded(const std::string& reference) {
  return Unavailable(reference);
}
Status WriteRosbag(const Dataset&, ImageLoader*, const BagTopics&, const std::string& path,
                   uint32_t) {
  return Unavailable(path);
}

}  // namespace ratslam::dataset
