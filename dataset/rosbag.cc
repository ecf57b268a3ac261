// Bag reading and writing through Debian's librosbag-storage-dev. Compiled as C++17: the ROS 1
// message headers Debian ships use std::allocator<void>::rebind, which C++20 removed.
#include "dataset/rosbag.h"

#include <console_bridge/console.h>
#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>

#include "common/file_util.h"
#include "dataset/bag_common.h"
#include "dataset/ros_image.h"
#include "dataset/rosbag_check.h"

namespace ratslam::dataset {
namespace fs = std::filesystem;

namespace {

// Nanoseconds of the header stamp, or of the record time where the stamp is zero (unset).
int64_t Nanoseconds(const ros::Time& stamp, const ros::Time& record) {
  const ros::Time& t = stamp.isZero() ? record : stamp;
  return int64_t{t.sec} * 1000000000 + int64_t{t.nsec};
}

constexpr const char* kCompressedImage = "sensor_msgs/CompressedImage";
constexpr const char* kRawImage = "sensor_msgs/Image";
constexpr const char* kOdometry = "nav_msgs/Odometry";
constexpr const char* kPoseStamped = "geometry_msgs/PoseStamped";
constexpr const char* kImu = "sensor_msgs/Imu";

RawImageView ViewOf(const sensor_msgs::Image& msg) {
  RawImageView v;
  v.height = msg.height;
  v.width = msg.width;
  v.encoding = msg.encoding;
  v.big_endian = msg.is_bigendian != 0;
  v.step = msg.step;
  v.data = msg.data.data();
  v.size = msg.data.size();
  return v;
}

// librosbag logs through console_bridge, to stdout and stderr; library code prints nothing
// (its errors reach the caller as exceptions, turned into messages here).
void SilenceRosLogging() {
  static const bool silenced = [] {
    console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
    return true;
  }();
  (void)silenced;
}

Status BagError(const std::string& path, const std::exception& e) {
  return Status::Error(path + ": not a readable ROS bag (truncated or corrupted?): " + e.what());
}

// librosbag deserialises a message by trusting its array lengths: it resizes a vector to the
// length a message claims before checking that the bytes are there, so a 20 kB bag whose image
// claims 4 GB of data allocated 4 GB (a fuzzer finding). Before instantiating, the message's own
// bytes are walked by its type's layout: every string or array length must fit in what is left.
// Layout letters: 'H' a std_msgs/Header (seq, stamp, frame_id), 'S' a string or uint8[], 'u' a
// uint32, 'b' a uint8, 'd' a float64.
bool LayoutFits(const std::vector<uint8_t>& bytes, const char* layout) {
  size_t p = 0;
  auto take = [&](size_t n) {
    if (n > bytes.size() - p) return false;
    p += n;
    return true;
  };
  auto string = [&] {
    if (!take(4)) return false;
    uint32_t n = 0;
    for (int k = 3; k >= 0; --k) n = (n << 8) | bytes[p - 4 + static_cast<size_t>(k)];
    return take(n);
  };
  for (const char* c = layout; *c; ++c) {
    const bool ok = *c == 'H'   ? take(12) && string()
                    : *c == 'S' ? string()
                    : *c == 'u' ? take(4)
                    : *c == 'b' ? take(1)
                                : take(8);
    if (!ok) return false;
  }
  return true;
}

template <typename T>
const char* LayoutOf();
// header, format, data
template <>
const char* LayoutOf<sensor_msgs::CompressedImage>() {
  return "HSS";
}
// header, height, width, encoding, is_bigendian, step, data
template <>
const char* LayoutOf<sensor_msgs::Image>() {
  return "HuuSbuS";
}
// header, child_frame_id, pose (7) + covariance (36), twist (6) + covariance (36)
template <>
const char* LayoutOf<nav_msgs::Odometry>() {
  return "HS"
         "ddddddd"
         "dddddddddddddddddddddddddddddddddddd"
         "dddddd"
         "dddddddddddddddddddddddddddddddddddd";
}
// header, pose (7)
template <>
const char* LayoutOf<geometry_msgs::PoseStamped>() {
  return "Hddddddd";
}

// header, orientation (4) + covariance (9), angular velocity (3) + covariance (9), linear
// acceleration (3) + covariance (9)
template <>
const char* LayoutOf<sensor_msgs::Imu>() {
  return "H"
         "ddddddddddddd"
         "dddddddddddd"
         "dddddddddddd";
}

// m.instantiate<T>() once the message's lengths are known to fit; throws otherwise (the callers
// turn exceptions into errors naming the bag).
template <typename T>
boost::shared_ptr<T> Instantiate(const rosbag::MessageInstance& m) {
  if (!m.isType<T>()) return nullptr;  // as instantiate: the caller names the type it wanted
  std::vector<uint8_t> bytes(m.size());
  ros::serialization::OStream stream(bytes.data(), static_cast<uint32_t>(bytes.size()));
  m.write(stream);
  if (!LayoutFits(bytes, LayoutOf<T>())) {
    throw std::runtime_error("message " + m.getDataType() + " on " + m.getTopic() +
                             " holds a field longer than the message");
  }
  return m.instantiate<T>();
}

}  // namespace

bool RosbagSupported() { return true; }

StatusOr<Dataset> ReadRosbag(const std::string& path, const BagTopics& topics) {
  std::string error;
  if (!topics.IsValid(&error)) return Status::Error(error);
  if (!IsRegularFile(path)) return Status::Error(path + ": not a file");
  if (!LooksLikeRosbag(path)) {
    return Status::Error(path + ": not a ROS 1 bag (it does not start with #ROSBAG V2.0)");
  }
  Dataset d;
  d.name = fs::path(path).stem().string();
  d.folder = path;  // where it was read from; the images' references are absolute
  d.image_folder = "";
  RATSLAM_RETURN_IF_ERROR(CheckRosbagStructure(path));
  SilenceRosLogging();
  const std::string reference = fs::absolute(path).string() + "#";
  BagDatasetBuilder builder;
  try {
    rosbag::Bag bag;
    bag.open(path, rosbag::bagmode::Read);
    rosbag::View view(bag);
    std::map<std::string, std::string> topic_types;
    for (const rosbag::ConnectionInfo* c : view.getConnections()) {
      auto [it, inserted] = topic_types.emplace(c->topic, c->datatype);
      if (!inserted && it->second != c->datatype) {
        return Status::Error(path + ": topic " + c->topic + " carries both " + it->second +
                             " and " + c->datatype);
      }
    }
    StatusOr<SelectedBagTopics> selected_topics = SelectBagTopics(
        path, topics, topic_types,
        {{kCompressedImage, kRawImage}, {kOdometry}, {kPoseStamped, kOdometry}, {kImu}});
    if (!selected_topics.ok()) return selected_topics.status();
    const std::string& image_topic = selected_topics->image;
    const std::string& odometry_topic = selected_topics->odometry;
    const std::string& truth_topic = selected_topics->ground_truth;
    const std::string& imu_topic = selected_topics->imu;
    uint64_t n = 0;
    for (const rosbag::MessageInstance& m : view) {
      const uint64_t index = n++;
      const std::string& topic = m.getTopic();
      if (topic != image_topic && topic != odometry_topic && topic != truth_topic &&
          topic != imu_topic) {
        continue;
      }
      const std::string where = path + ": message " + std::to_string(index) + " on " + topic;
      if (topic == image_topic) {
        int64_t time_ns = 0;
        if (m.getDataType() == kCompressedImage) {
          auto msg = Instantiate<sensor_msgs::CompressedImage>(m);
          if (!msg) return Status::Error(where + ": not a " + std::string(kCompressedImage));
          time_ns = Nanoseconds(msg->header.stamp, m.getTime());
        } else {
          auto msg = Instantiate<sensor_msgs::Image>(m);
          if (!msg) return Status::Error(where + ": not a " + std::string(kRawImage));
          time_ns = Nanoseconds(msg->header.stamp, m.getTime());
        }
        RATSLAM_RETURN_IF_ERROR(
            builder.AddImage(time_ns, topic, where, reference + std::to_string(index), index));
      } else if (topic == odometry_topic) {
        auto msg = Instantiate<nav_msgs::Odometry>(m);
        if (!msg) return Status::Error(where + ": not a " + std::string(kOdometry));
        RATSLAM_RETURN_IF_ERROR(builder.AddOdometry(Nanoseconds(msg->header.stamp, m.getTime()),
                                                    topic, where, msg->twist.twist.linear.x,
                                                    msg->twist.twist.angular.z));
      } else if (topic == imu_topic) {
        auto msg = Instantiate<sensor_msgs::Imu>(m);
        if (!msg) return Status::Error(where + ": not a " + std::string(kImu));
        const auto& q = msg->orientation;
        RATSLAM_RETURN_IF_ERROR(builder.AddCompass(Nanoseconds(msg->header.stamp, m.getTime()),
                                                   topic, where,
                                                   YawOfQuaternion(q.x, q.y, q.z, q.w)));
      } else {
        geometry_msgs::Pose pose;
        int64_t time_ns = 0;
        if (m.getDataType() == kPoseStamped) {
          auto msg = Instantiate<geometry_msgs::PoseStamped>(m);
          if (!msg) return Status::Error(where + ": not a " + std::string(kPoseStamped));
          time_ns = Nanoseconds(msg->header.stamp, m.getTime());
          pose = msg->pose;
        } else {
          auto msg = Instantiate<nav_msgs::Odometry>(m);
          if (!msg) return Status::Error(where + ": not a " + std::string(kOdometry));
          time_ns = Nanoseconds(msg->header.stamp, m.getTime());
          pose = msg->pose.pose;
        }
        const auto& q = pose.orientation;
        RATSLAM_RETURN_IF_ERROR(builder.AddGroundTruth(time_ns, topic, where, pose.position.x,
                                                       pose.position.y,
                                                       YawOfQuaternion(q.x, q.y, q.z, q.w)));
      }
    }
  } catch (const std::exception& e) {
    return BagError(path, e);
  }
  return std::move(builder).Finish(std::move(d), path);
}

class BagImageReader::Impl {
 public:
  // The message of `reference`, with the bag open; call with the mutex held.
  StatusOr<const rosbag::MessageInstance*> Find(const std::string& reference) {
    std::string path;
    uint64_t n = 0;
    if (!ParseBagImageReference(reference, &path, &n)) {
      return Status::Error(reference + ": not an image reference <bag>#<message>");
    }
    std::error_code ec;
    const auto written = fs::last_write_time(path, ec);
    const auto size = ec ? 0 : fs::file_size(path, ec);
    // Reopened when another bag is named or the file changed since it was indexed.
    if (path != path_ || !bag_ || written != written_ || size != size_) {
      written_ = written;
      size_ = size;
      bag_.reset();
      messages_.clear();
      path_.clear();
      if (!LooksLikeRosbag(path)) return Status::Error(path + ": not a ROS 1 bag");
      RATSLAM_RETURN_IF_ERROR(CheckRosbagStructure(path));
      SilenceRosLogging();
      try {
        auto bag = std::make_unique<rosbag::Bag>();
        bag->open(path, rosbag::bagmode::Read);
        rosbag::View view(*bag);
        std::vector<rosbag::MessageInstance> messages;
        messages.reserve(view.size());
        for (const rosbag::MessageInstance& m : view) messages.push_back(m);
        bag_ = std::move(bag);
        messages_ = std::move(messages);
        path_ = path;
      } catch (const std::exception& e) {
        return BagError(path, e);
      }
    }
    if (n >= messages_.size()) {
      return Status::Error(reference + ": the bag has " + std::to_string(messages_.size()) +
                           " messages");
    }
    return &messages_[n];
  }

  std::mutex mutex;

 private:
  std::string path_;
  fs::file_time_type written_{};
  uintmax_t size_ = 0;
  std::unique_ptr<rosbag::Bag> bag_;
  std::vector<rosbag::MessageInstance> messages_;
};

BagImageReader::BagImageReader() : impl_(std::make_unique<Impl>()) {}
BagImageReader::~BagImageReader() = default;

StatusOr<GrayImage> BagImageReader::Load(const std::string& reference) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  StatusOr<const rosbag::MessageInstance*> m = impl_->Find(reference);
  if (!m.ok()) return m.status();
  try {
    if ((*m)->getDataType() == kCompressedImage) {
      auto msg = Instantiate<sensor_msgs::CompressedImage>(**m);
      if (msg) {
        return GrayFromCompressedImage(msg->data.data(), msg->data.size(), msg->format, reference);
      }
    } else if ((*m)->getDataType() == kRawImage) {
      auto msg = Instantiate<sensor_msgs::Image>(**m);
      if (msg) return GrayFromRawImage(ViewOf(*msg), reference);
    }
  } catch (const std::exception& e) {
    return Status::Error(reference + ": cannot read the message: " + e.what());
  }
  return Status::Error(reference + ": message on " + (*m)->getTopic() + " is a " +
                       (*m)->getDataType() + ", not an image");
}

StatusOr<EncodedImage> BagImageReader::Encoded(const std::string& reference) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  StatusOr<const rosbag::MessageInstance*> m = impl_->Find(reference);
  if (!m.ok()) return m.status();
  try {
    if ((*m)->getDataType() == kCompressedImage) {
      auto msg = Instantiate<sensor_msgs::CompressedImage>(**m);
      if (msg) {
        EncodedImage out;
        out.extension = CompressedImageExtension(msg->data.data(), msg->data.size(), msg->format);
        if (out.extension.empty()) {
          return Status::Error(reference + ": compressed image format '" + msg->format +
                               "' is neither PNG nor JPEG");
        }
        out.bytes = msg->data;
        return out;
      }
    } else if ((*m)->getDataType() == kRawImage) {
      auto msg = Instantiate<sensor_msgs::Image>(**m);
      if (msg) return PngFromRawImage(ViewOf(*msg), reference);
    }
  } catch (const std::exception& e) {
    return Status::Error(reference + ": cannot read the message: " + e.what());
  }
  return Status::Error(reference + ": message on " + (*m)->getTopic() + " is a " +
                       (*m)->getDataType() + ", not an image");
}

Status WriteRosbag(const Dataset& dataset, ImageLoader* images, const BagTopics& topics,
                   const std::string& path, uint32_t time_offset_s) {
  std::string error;
  if (!topics.IsValid(&error)) return Status::Error(error);
  if (!dataset.wifi.empty() || !dataset.compass.empty() || !dataset.pressure.empty()) {
    return Status::Error(path + ": Wi-Fi scans, compass and barometer readings are not written " +
                         "to bags; a bag holds images, odometry and ground truth");
  }
  if (!dataset.images.empty() && topics.image_topic.empty()) {
    return Status::Error(path + ": name the image topic");
  }
  if (!dataset.odometry.empty() && topics.odometry_topic.empty()) {
    return Status::Error(path + ": name the odometry topic");
  }
  const double latest = 4294967295.0 - time_offset_s;
  for (const Event& e : MergeEvents(dataset)) {
    if (!(e.time_s >= 0.0 && e.time_s < latest)) {
      return Status::Error(path + ": time " + std::to_string(e.time_s) +
                           " s is outside what a ROS time can hold after the offset");
    }
  }
  for (const GroundTruthRow& row : dataset.ground_truth) {
    if (!(row.time_s >= 0.0 && row.time_s < latest)) {
      return Status::Error(path + ": ground-truth time " + std::to_string(row.time_s) +
                           " s is outside what a ROS time can hold after the offset");
    }
  }
  SilenceRosLogging();
  const std::string temporary = path + ".partial";
  // Whole seconds and nanoseconds apart, so that the reader gets the times back to the
  // nanosecond (ros::Time(1e9 + t) would round t to about 0.1 us).
  auto stamp = [&](double t) {
    const double whole = std::floor(t);
    int64_t nsec = std::llround((t - whole) * 1e9);
    int64_t sec = int64_t{time_offset_s} + static_cast<int64_t>(whole);
    if (nsec >= 1000000000) {
      nsec -= 1000000000;
      ++sec;
    }
    return ros::Time(static_cast<uint32_t>(sec), static_cast<uint32_t>(nsec));
  };
  try {
    rosbag::Bag bag;
    bag.open(temporary, rosbag::bagmode::Write);
    double x = 0.0, y = 0.0, theta = 0.0, last_t = 0.0;
    bool have_last = false;
    for (const Event& e : MergeEvents(dataset)) {
      if (e.type == EventType::kImage) {
        const ImageRow& row = dataset.images[e.index];
        StatusOr<GrayImage> image = images->Load(dataset.ImagePath(row));
        if (!image.ok()) return image.status();
        sensor_msgs::CompressedImage msg;
        msg.header.stamp = stamp(row.time_s);
        msg.header.seq = e.index;
        msg.header.frame_id = "camera";
        msg.format = "mono8; png compressed ";
        const cv::Mat g(image->height, image->width, CV_8U, image->pixels.data());
        if (!cv::imencode(".png", g, msg.data)) return Status::Error(path + ": PNG encoding");
        bag.write(NormaliseRosTopic(topics.image_topic), msg.header.stamp, msg);
      } else if (e.type == EventType::kOdometry) {
        const OdometryRow& row = dataset.odometry[e.index];
        const double dt = have_last ? row.time_s - last_t : 0.0;
        theta += row.turn_rate_rad_per_s * dt;
        x += row.forward_speed_m_per_s * dt * std::cos(theta);
        y += row.forward_speed_m_per_s * dt * std::sin(theta);
        last_t = row.time_s;
        have_last = true;
        nav_msgs::Odometry msg;
        msg.header.stamp = stamp(row.time_s);
        msg.header.seq = e.index;
        msg.header.frame_id = "odom";
        msg.child_frame_id = "base_link";
        msg.pose.pose.position.x = x;
        msg.pose.pose.position.y = y;
        msg.pose.pose.orientation.z = std::sin(theta / 2);
        msg.pose.pose.orientation.w = std::cos(theta / 2);
        msg.twist.twist.linear.x = row.forward_speed_m_per_s;
        msg.twist.twist.angular.z = row.turn_rate_rad_per_s;
        bag.write(NormaliseRosTopic(topics.odometry_topic), msg.header.stamp, msg);
      }
    }
    if (!topics.ground_truth_topic.empty()) {
      for (size_t i = 0; i < dataset.ground_truth.size(); ++i) {
        const GroundTruthRow& row = dataset.ground_truth[i];
        geometry_msgs::PoseStamped msg;
        msg.header.stamp = stamp(row.time_s);
        msg.header.seq = static_cast<uint32_t>(i);
        msg.header.frame_id = "world";
        msg.pose.position.x = row.x_m;
        msg.pose.position.y = row.y_m;
        msg.pose.orientation.z = std::sin(row.theta_rad / 2);
        msg.pose.orientation.w = std::cos(row.theta_rad / 2);
        bag.write(NormaliseRosTopic(topics.ground_truth_topic), msg.header.stamp, msg);
      }
    }
    bag.close();
  } catch (const std::exception& e) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    return Status::Error(path + ": cannot write the bag: " + e.what());
  }
  std::error_code ec;
  fs::rename(temporary, path, ec);
  if (ec) return Status::Error(path + ": cannot move the finished bag into place: " + ec.message());
  return Status::Ok();
}

}  // namespace ratslam::dataset
