// ROS 2 messages in CDR, the serialisation rosbag2 stores (OMG's Common Data Representation,
// version 1, as ROS 2's default middleware writes it): a 4-byte encapsulation header (0x00 0x00
// big-endian, 0x00 0x01 little-endian), then each field aligned to its own size, counted from
// after that header; strings and sequences carry a uint32 count (a string's includes its NUL).
// Only the fields the data sets need are kept. Every decoder checks every length against the
// bytes that are there and names the field that does not fit.
#ifndef RATSLAM_DATASET_ROS2_MESSAGES_H_
#define RATSLAM_DATASET_ROS2_MESSAGES_H_

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "common/status.h"

namespace ratslam::dataset {

// builtin_interfaces/msg/Time
struct Ros2Time {
  int32_t sec = 0;
  uint32_t nanosec = 0;
  int64_t Nanoseconds() const { return int64_t{sec} * 1000000000 + int64_t{nanosec}; }
  bool IsZero() const { return sec == 0 && nanosec == 0; }
};

struct Ros2Quaternion {
  double x = 0.0, y = 0.0, z = 0.0, w = 1.0;
};

// sensor_msgs/msg/Image
struct Ros2Image {
  Ros2Time stamp;
  uint32_t height = 0;
  uint32_t width = 0;
  std::string encoding;
  bool big_endian = false;
  uint32_t step = 0;
  std::vector<uint8_t> data;
};

// sensor_msgs/msg/CompressedImage
struct Ros2CompressedImage {
  Ros2Time stamp;
  std::string format;
  std::vector<uint8_t> data;
};

// nav_msgs/msg/Odometry: the pose and the twist's forward and turn rates.
struct Ros2Odometry {
  Ros2Time stamp;
  double x_m = 0.0, y_m = 0.0;
  Ros2Quaternion orientation;
  double forward_speed_m_per_s = 0.0;  // twist.twist.linear.x
  double turn_rate_rad_per_s = 0.0;    // twist.twist.angular.z
};

// geometry_msgs/msg/PoseStamped
struct Ros2PoseStamped {
  Ros2Time stamp;
  double x_m = 0.0, y_m = 0.0;
  Ros2Quaternion orientation;
};

// sensor_msgs/msg/Imu: its orientation.
struct Ros2Imu {
  Ros2Time stamp;
  Ros2Quaternion orientation;
};

// The std_msgs/msg/Header stamp every one of the messages above starts with.
StatusOr<Ros2Time> DecodeRos2Stamp(const uint8_t* data, size_t size, const std::string& where);
StatusOr<Ros2Image> DecodeRos2Image(const uint8_t* data, size_t size, const std::string& where);
StatusOr<Ros2CompressedImage> DecodeRos2CompressedImage(const uint8_t* data, size_t size,
                                                        const std::string& where);
StatusOr<Ros2Odometry> DecodeRos2Odometry(const uint8_t* data, size_t size,
                                          const std::string& where);
StatusOr<Ros2PoseStamped> DecodeRos2PoseStamped(const uint8_t* data, size_t size,
                                                const std::string& where);
StatusOr<Ros2Imu> DecodeRos2Imu(const uint8_t* data, size_t size, const std::string& where);

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_ROS2_MESSAGES_H_
