// ROS 1 bags (format 2.0) as data sets: camera images (sensor_msgs/CompressedImage or
// sensor_msgs/Image), odometry (nav_msgs/Odometry: header.stamp, twist.twist.linear.x and
// twist.twist.angular.z, as OpenRatSLAM reads it; the pose is ignored) and, optionally, ground
// truth (geometry_msgs/PoseStamped or nav_msgs/Odometry poses) and a compass (the yaw of
// sensor_msgs/Imu orientations, counter-clockwise from x). Read offline through Debian's
// librosbag-storage-dev; no roscore. Builds without it answer every call with an error that says
// how to get it.
//
// Images stay in the bag: a data set read from a bag names each image `<bag path>#<n>`, message
// n of the bag in time order, and FileImageLoader decodes such references from the bag.
#ifndef RATSLAM_DATASET_ROSBAG_H_
#define RATSLAM_DATASET_ROSBAG_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/schema.h"
#include "common/status.h"
#include "dataset/dataset.h"
#include "dataset/image_loader.h"

namespace ratslam::dataset {

// Which topics of a bag make the data set ([bag] in the configuration). An empty topic means
// "the bag's only topic of that type".
struct BagTopics {
  std::string image_topic;         // also found with "/compressed" appended (image_transport)
  std::string odometry_topic;      // empty and none in the bag: no odometry (visual odometry)
  std::string ground_truth_topic;  // empty: no ground truth
  std::string imu_topic;           // empty: no compass from an IMU

  bool IsValid(std::string* error) const;

  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("image_topic", image_topic,
      "camera topic (sensor_msgs/CompressedImage or Image; X/compressed is found for X); "
      "empty: the bag's only image topic",
      schema::Any());
    v("odometry_topic", odometry_topic,
      "nav_msgs/Odometry topic; empty: the bag's only one (none: no odometry)", schema::Any());
    v("ground_truth_topic", ground_truth_topic,
      "geometry_msgs/PoseStamped or nav_msgs/Odometry poses as ground truth; empty: none",
      schema::Any());
    v("imu_topic", imu_topic,
      "sensor_msgs/Imu topic whose orientation's yaw is the compass heading; empty: none",
      schema::Any());
  }
};

// Whether this build reads bags (librosbag-storage-dev was found at configure time).
bool RosbagSupported();

// A topic name as ROS resolves it: relative names under "/", doubled slashes collapsed
// ("/newcollege//odom" is "/newcollege/odom"), no trailing slash.
std::string NormaliseRosTopic(const std::string& name);

// Whether the file starts like a ROS 1 bag ("#ROSBAG V2.0").
bool LooksLikeRosbag(const std::string& path);

// Reads the selected topics. Times are header stamps (the bag's record time where a stamp is
// zero) in seconds after the earliest selected message. Errors name the bag, the topic and the
// message; a stamp that goes backwards within a topic is an error. A truncated or corrupted bag
// is an error, never a partial data set.
StatusOr<Dataset> ReadRosbag(const std::string& path, const BagTopics& topics);

// `path` names an image inside a bag (`<file>.bag#<n>`): splits it.
bool ParseBagImageReference(const std::string& path, std::string* bag, uint64_t* message);

// An image's bytes as stored: a CompressedImage's data with the extension its format implies
// ("jpg", "png", ...); a raw Image encoded as a lossless grey PNG.
struct EncodedImage {
  std::vector<uint8_t> bytes;
  std::string extension;
};

// Reads images out of bags by reference, keeping the last bag open. Thread-safe.
class BagImageReader {
 public:
  BagImageReader();
  ~BagImageReader();
  BagImageReader(const BagImageReader&) = delete;
  BagImageReader& operator=(const BagImageReader&) = delete;

  StatusOr<GrayImage> Load(const std::string& reference);
  StatusOr<EncodedImage> Encoded(const std::string& reference);

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

// Writes `dataset` as a bag: each image as a CompressedImage (PNG, grey) on
// topics.image_topic, odometry as nav_msgs/Odometry on topics.odometry_topic and ground truth as
// geometry_msgs/PoseStamped on topics.ground_truth_topic (when named), stamped `time_offset_s`
// plus the data set's times (to the nanosecond). Times must be non-negative and below 4e9 s minus
// the offset. Wi-Fi and compass streams have no standard ROS message and are
// refused. For tests and for people who want our synthetic worlds in their ROS tools.
Status WriteRosbag(const Dataset& dataset, ImageLoader* images, const BagTopics& topics,
                   const std::string& path, uint32_t time_offset_s = 1000000000);

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_ROSBAG_H_
