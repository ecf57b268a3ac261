// Message layouts are those of the ROS 2 message packages (std_msgs, builtin_interfaces,
// geometry_msgs, sensor_msgs, nav_msgs) as of Humble to Jazzy, which have not changed them.
#include "dataset/ros2_messages.h"

#include <cstring>

namespace ratslam::dataset {
namespace {

class CdrReader {
 public:
  CdrReader(const uint8_t* data, size_t size, const std::string& where)
      : data_(data), size_(size), where_(where) {}

  Status Start() {
    if (size_ < 4) return Error("", "shorter than CDR's 4-byte encapsulation header");
    if (data_[0] != 0 || data_[1] > 1) {
      return Error("", "encapsulation " + std::to_string(data_[0]) + " " +
                           std::to_string(data_[1]) +
                           " is not plain CDR (0 0 big-endian or 0 1 little-endian)");
    }
    little_ = data_[1] == 1;
    at_ = 4;
    return Status::Ok();
  }

  template <typename T>
  Status Read(const char* field, T* out) {
    const size_t pad = (sizeof(T) - (at_ - 4) % sizeof(T)) % sizeof(T);
    RATSLAM_RETURN_IF_ERROR(Need(field, pad + sizeof(T)));
    at_ += pad;
    uint8_t bytes[sizeof(T)];
    for (size_t k = 0; k < sizeof(T); ++k) {
      bytes[k] = little_ ? data_[at_ + k] : data_[at_ + sizeof(T) - 1 - k];
    }
    std::memcpy(out, bytes, sizeof(T));
    at_ += sizeof(T);
    return Status::Ok();
  }

  Status String(const char* field, std::string* out) {
    uint32_t n = 0;
    RATSLAM_RETURN_IF_ERROR(Read(field, &n));
    RATSLAM_RETURN_IF_ERROR(Need(field, n));
    // The count includes a closing NUL; writers that leave it out are read too.
    size_t length = n;
    if (length > 0 && data_[at_ + length - 1] == 0) --length;
    out->assign(reinterpret_cast<const char*>(data_ + at_), length);
    at_ += n;
    return Status::Ok();
  }

  Status Bytes(const char* field, std::vector<uint8_t>* out) {
    uint32_t n = 0;
    RATSLAM_RETURN_IF_ERROR(Read(field, &n));
    RATSLAM_RETURN_IF_ERROR(Need(field, n));
    out->assign(data_ + at_, data_ + at_ + n);
    at_ += n;
    return Status::Ok();
  }

  Status SkipDoubles(const char* field, int count) {
    double ignored = 0.0;
    for (int i = 0; i < count; ++i) RATSLAM_RETURN_IF_ERROR(Read(field, &ignored));
    return Status::Ok();
  }

  Status Header(Ros2Time* stamp) {
    RATSLAM_RETURN_IF_ERROR(Read("header.stamp.sec", &stamp->sec));
    RATSLAM_RETURN_IF_ERROR(Read("header.stamp.nanosec", &stamp->nanosec));
    if (stamp->nanosec >= 1000000000u) {
      return Error("header.stamp.nanosec", std::to_string(stamp->nanosec) + " is 1 s or more");
    }
    std::string frame_id;
    return String("header.frame_id", &frame_id);
  }

  Status Quaternion(const char* field, Ros2Quaternion* q) {
    RATSLAM_RETURN_IF_ERROR(Read(field, &q->x));
    RATSLAM_RETURN_IF_ERROR(Read(field, &q->y));
    RATSLAM_RETURN_IF_ERROR(Read(field, &q->z));
    return Read(field, &q->w);
  }

 private:
  Status Need(const char* field, size_t n) const {
    if (n > size_ - at_) {
      return Error(field, "runs past the end of the message (" + std::to_string(size_) +
                              " bytes; " + std::to_string(n) + " wanted at byte " +
                              std::to_string(at_) + ")");
    }
    return Status::Ok();
  }
  Status Error(const std::string& field, const std::string& what) const {
    return Status::Error(where_ + (field.empty() ? "" : ": field " + field) + ": " + what);
  }

  const uint8_t* data_;
  size_t size_;
  size_t at_ = 0;
  bool little_ = true;
  const std::string& where_;
};

}  // namespace

StatusOr<Ros2Time> DecodeRos2Stamp(const uint8_t* data, size_t size, const std::string& where) {
  CdrReader r(data, size, where);
  RATSLAM_RETURN_IF_ERROR(r.Start());
  Ros2Time stamp;
  RATSLAM_RETURN_IF_ERROR(r.Header(&stamp));
  return stamp;
}

StatusOr<Ros2Image> DecodeRos2Image(const uint8_t* data, size_t size, const std::string& where) {
  CdrReader r(data, size, where);
  RATSLAM_RETURN_IF_ERROR(r.Start());
  Ros2Image m;
  uint8_t big_endian = 0;
  RATSLAM_RETURN_IF_ERROR(r.Header(&m.stamp));
  RATSLAM_RETURN_IF_ERROR(r.Read("height", &m.height));
  RATSLAM_RETURN_IF_ERROR(r.Read("width", &m.width));
  RATSLAM_RETURN_IF_ERROR(r.String("encoding", &m.encoding));
  RATSLAM_RETURN_IF_ERROR(r.Read("is_bigendian", &big_endian));
  RATSLAM_RETURN_IF_ERROR(r.Read("step", &m.step));
  RATSLAM_RETURN_IF_ERROR(r.Bytes("data", &m.data));
  m.big_endian = big_endian != 0;
  return m;
}

StatusOr<Ros2CompressedImage> DecodeRos2CompressedImage(const uint8_t* data, size_t size,
                                                        const std::string& where) {
  CdrReader r(data, size, where);
  RATSLAM_RETURN_IF_ERROR(r.Start());
  Ros2CompressedImage m;
  RATSLAM_RETURN_IF_ERROR(r.Header(&m.stamp));
  RATSLAM_RETURN_IF_ERROR(r.String("format", &m.format));
  RATSLAM_RETURN_IF_ERROR(r.Bytes("data", &m.data));
  return m;
}

StatusOr<Ros2Odometry> DecodeRos2Odometry(const uint8_t* data, size_t size,
                                          const std::string& where) {
  CdrReader r(data, size, where);
  RATSLAM_RETURN_IF_ERROR(r.Start());
  Ros2Odometry m;
  std::string child_frame_id;
  double z = 0.0;
  RATSLAM_RETURN_IF_ERROR(r.Header(&m.stamp));
  RATSLAM_RETURN_IF_ERROR(r.String("child_frame_id", &child_frame_id));
  RATSLAM_RETURN_IF_ERROR(r.Read("pose.pose.position.x", &m.x_m));
  RATSLAM_RETURN_IF_ERROR(r.Read("pose.pose.position.y", &m.y_m));
  RATSLAM_RETURN_IF_ERROR(r.Read("pose.pose.position.z", &z));
  RATSLAM_RETURN_IF_ERROR(r.Quaternion("pose.pose.orientation", &m.orientation));
  RATSLAM_RETURN_IF_ERROR(r.SkipDoubles("pose.covariance", 36));
  RATSLAM_RETURN_IF_ERROR(r.Read("twist.twist.linear.x", &m.forward_speed_m_per_s));
  RATSLAM_RETURN_IF_ERROR(r.SkipDoubles("twist.twist.linear.y/z", 2));
  RATSLAM_RETURN_IF_ERROR(r.SkipDoubles("twist.twist.angular.x/y", 2));
  RATSLAM_RETURN_IF_ERROR(r.Read("twist.twist.angular.z", &m.turn_rate_rad_per_s));
  RATSLAM_RETURN_IF_ERROR(r.SkipDoubles("twist.covariance", 36));
  return m;
}

StatusOr<Ros2PoseStamped> DecodeRos2PoseStamped(const uint8_t* data, size_t size,
                                                const std::string& where) {
  CdrReader r(data, size, where);
  RATSLAM_RETURN_IF_ERROR(r.Start());
  Ros2PoseStamped m;
  double z = 0.0;
  RATSLAM_RETURN_IF_ERROR(r.Header(&m.stamp));
  RATSLAM_RETURN_IF_ERROR(r.Read("pose.position.x", &m.x_m));
  RATSLAM_RETURN_IF_ERROR(r.Read("pose.position.y", &m.y_m));
  RATSLAM_RETURN_IF_ERROR(r.Read("pose.position.z", &z));
  RATSLAM_RETURN_IF_ERROR(r.Quaternion("pose.orientation", &m.orientation));
  return m;
}

StatusOr<Ros2Imu> DecodeRos2Imu(const uint8_t* data, size_t size, const std::string& where) {
  CdrReader r(data, size, where);
  RATSLAM_RETURN_IF_ERROR(r.Start());
  Ros2Imu m;
  RATSLAM_RETURN_IF_ERROR(r.Header(&m.stamp));
  RATSLAM_RETURN_IF_ERROR(r.Quaternion("orientation", &m.orientation));
  RATSLAM_RETURN_IF_ERROR(r.SkipDoubles("orientation_covariance", 9));
  RATSLAM_RETURN_IF_ERROR(r.SkipDoubles("angular_velocity", 3));
  RATSLAM_RETURN_IF_ERROR(r.SkipDoubles("angular_velocity_covariance", 9));
  RATSLAM_RETURN_IF_ERROR(r.SkipDoubles("linear_acceleration", 3));
  RATSLAM_RETURN_IF_ERROR(r.SkipDoubles("linear_acceleration_covariance", 9));
  return m;
}

}  // namespace ratslam::dataset
