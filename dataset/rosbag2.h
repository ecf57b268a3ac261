// ROS 2 bags as data sets, read without ROS 2: an MCAP file (`.mcap`), a rosbag2 sqlite3 file
// (`.db3`), or a rosbag2 folder (metadata.yaml naming its .mcap or .db3 files, read in order).
// The streams and the [bag] topic options are those of ROS 1 bags (dataset/rosbag.h) with
// ROS 2's message types: sensor_msgs/msg/CompressedImage or Image (mono8, rgb8, bgr8, mono16,
// rgba8, bgra8) as camera, nav_msgs/msg/Odometry (twist.twist.linear.x and angular.z) as
// odometry, geometry_msgs/msg/PoseStamped or nav_msgs/msg/Odometry as ground truth, and the yaw of
// sensor_msgs/msg/Imu orientations as compass. Messages must be CDR
// (dataset/ros2_messages.h).
//
// Times are header stamps (the log time where a stamp is zero) in seconds after the earliest
// selected message; a stamp going backwards within a topic is an error. Images stay in the bag:
// the data set names each `<file>#<n>` (n: the message's place in the MCAP file's time order, or
// its row id in the sqlite3 file), which FileImageLoader reads through Ros2ImageReader.
#ifndef RATSLAM_DATASET_ROSBAG2_H_
#define RATSLAM_DATASET_ROSBAG2_H_

#include <cstdint>
#include <memory>
#include <string>

#include "common/status.h"
#include "dataset/dataset.h"
#include "dataset/image_loader.h"
#include "dataset/rosbag.h"

namespace ratslam::dataset {

// An MCAP file, an SQLite file, or a folder holding metadata.yaml.
bool LooksLikeRos2Bag(const std::string& path);

// Errors name the file, the message (and for MCAP the record's byte offset) and the field.
StatusOr<Dataset> ReadRos2Bag(const std::string& path, const BagTopics& topics);

// `reference` names a message of a ROS 2 bag file (`<file>.mcap#<n>` or `<file>.db3#<n>`).
bool ParseRos2ImageReference(const std::string& reference, std::string* file, uint64_t* message);

// Reads images out of ROS 2 bag files by reference, keeping the last file open. Thread-safe.
class Ros2ImageReader {
 public:
  Ros2ImageReader();
  ~Ros2ImageReader();
  Ros2ImageReader(const Ros2ImageReader&) = delete;
  Ros2ImageReader& operator=(const Ros2ImageReader&) = delete;

  StatusOr<GrayImage> Load(const std::string& reference);
  // As stored: a CompressedImage's bytes; a raw image as a grey PNG.
  StatusOr<EncodedImage> Encoded(const std::string& reference);

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_ROSBAG2_H_
