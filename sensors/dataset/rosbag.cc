// Bag reading and writing through Debian's librosbag-storage-dev. Compiled as C++17: the ROS 1
// message headers Debian ships use std::allocator<void>::rebind, which C++20 removed.
#include "sensors/dataset/rosbag.h"

#include <console_bridge/console.h>
#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>

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
#include "sensors/dataset/opencv_gray.h"
#include "sensors/dataset/rosbag_check.h"

namespace ratslam {
namespace fs = std::filesystem;

namespace {

constexpr const char* kCompressedImage = "sensor_msgs/CompressedImage";
constexpr const char* kRawImage = "sensor_msgs/Image";
constexpr const char* kOdometry = "nav_msgs/Odometry";
constexpr const char* kPoseStamped = "geometry_msgs/PoseStamped";

std::string Quoted(const std::set<std::string>& names) {
  if (names.empty()) return "none";
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

// Nanoseconds of the header stamp, or of the record time where the stamp is zero (unset).
int64_t Nanoseconds(const ros::Time& stamp, const ros::Time& record) {
  const ros::Time& t = stamp.isZero() ? record : stamp;
  return int64_t{t.sec} * 1000000000 + int64_t{t.nsec};
}

// Picks the topic for one stream. `types` are the message types it accepts.
StatusOr<std::string> ResolveTopic(const std::string& bag, const std::string& what,
                                   const std::string& key, const std::string& wanted,
                                   const std::map<std::string, std::string>& topic_types,
                                   const std::set<std::string>& types, bool try_compressed,
                                   bool required_when_named) {
  std::set<std::string> candidates;
  std::set<std::string> all;
  for (const auto& [topic, type] : topic_types) {
    all.insert(topic + " (" + type + ")");
    if (types.count(type)) candidates.insert(topic);
  }
  if (wanted.empty()) {
    if (candidates.size() > 1) {
      return Status::Error(bag + ": " + std::to_string(candidates.size()) + " " + what +
                           " topics (" + Quoted(candidates) + "): choose one with [bag] " + key);
    }
    return candidates.empty() ? std::string() : *candidates.begin();
  }
  std::string name = NormaliseRosTopic(wanted);
  if (!topic_types.count(name) && try_compressed && topic_types.count(name + "/compressed")) {
    name += "/compressed";
  }
  auto it = topic_types.find(name);
  if (it == topic_types.end()) {
    if (!required_when_named) return std::string();
    return Status::Error(bag + ": no topic " + name + " ([bag] " + key + "); the bag has " +
                         Quoted(all));
  }
  if (!types.count(it->second)) {
    return Status::Error(bag + ": topic " + name + " ([bag] " + key + ") carries " + it->second +
                         ", not " + what + " messages (" + Quoted(types) + ")");
  }
  return name;
}

StatusOr<GrayImage> DecodeCompressed(const sensor_msgs::CompressedImage& msg,
                                     const std::string& where) {
  if (msg.data.empty()) return Status::Error(where + ": empty compressed image");
  cv::Mat mat;
  try {
    const cv::Mat raw(1, static_cast<int>(msg.data.size()), CV_8U,
                      const_cast<uint8_t*>(msg.data.data()));
    mat = cv::imdecode(raw, cv::IMREAD_GRAYSCALE);
  } catch (const cv::Exception& e) {
    return Status::Error(where + ": cannot decode image (format '" + msg.format +
                         "'): " + e.what());
  }
  if (mat.empty()) {
    return Status::Error(where + ": cannot decode image (format '" + msg.format + "')");
  }
  return GrayFromMat(mat, where);
}

// A raw image as an OpenCV matrix in BGR(A) or grey, after checking its size fields.
StatusOr<cv::Mat> RawToMat(const sensor_msgs::Image& msg, const std::string& where) {
  const std::string& enc = msg.encoding;
  int channels = 0, depth_bytes = 1;
  if (enc == "mono8" || enc == "8UC1") {
    channels = 1;
  } else if (enc == "mono16" || enc == "16UC1") {
    channels = 1;
    depth_bytes = 2;
  } else if (enc == "bgr8" || enc == "rgb8" || enc == "8UC3") {
    channels = 3;
  } else if (enc == "bgra8" || enc == "rgba8" || enc == "8UC4") {
    channels = 4;
  } else {
    return Status::Error(where + ": image encoding '" + enc +
                         "' is not read (mono8, mono16, bgr8, rgb8, bgra8, rgba8)");
  }
  const uint64_t row_bytes = uint64_t{msg.width} * static_cast<uint64_t>(channels * depth_bytes);
  if (msg.width == 0 || msg.height == 0 || msg.width > 65535 || msg.height > 65535) {
    return Status::Error(where + ": image size " + std::to_string(msg.width) + "x" +
                         std::to_string(msg.height) + " out of range");
  }
  if (msg.step < row_bytes || uint64_t{msg.step} * msg.height > msg.data.size()) {
    return Status::Error(where + ": image step " + std::to_string(msg.step) + " and height " +
                         std::to_string(msg.height) + " do not fit its " +
                         std::to_string(msg.data.size()) + " bytes of data");
  }
  const int w = static_cast<int>(msg.width), h = static_cast<int>(msg.height);
  cv::Mat mat(h, w, CV_8UC(channels));
  for (int r = 0; r < h; ++r) {
    const uint8_t* src = msg.data.data() + static_cast<size_t>(r) * msg.step;
    uint8_t* dst = mat.ptr<uint8_t>(r);
    if (depth_bytes == 1) {
      std::copy(src, src + static_cast<size_t>(w) * channels, dst);
    } else {
      for (int c = 0; c < w; ++c) {  // the high byte of each 16-bit value
        dst[c] = msg.is_bigendian ? src[2 * c] : src[2 * c + 1];
      }
    }
  }
  if (enc == "rgb8") cv::cvtColor(mat, mat, cv::COLOR_RGB2BGR);
  if (enc == "rgba8") cv::cvtColor(mat, mat, cv::COLOR_RGBA2BGRA);
  return mat;
}

std::string ExtensionOf(const sensor_msgs::CompressedImage& msg) {
  std::string format;
  for (char c : msg.format)
    format += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const auto& d = msg.data;
  if (d.size() >= 8 && d[0] == 0x89 && d[1] == 'P' && d[2] == 'N' && d[3] == 'G') return "png";
  if (d.size() >= 3 && d[0] == 0xFF && d[1] == 0xD8 && d[2] == 0xFF) return "jpg";
  if (format.find("png") != std::string::npos) return "png";
  if (format.find("jpeg") != std::string::npos || format.find("jpg") != std::string::npos) {
    return "jpg";
  }
  return "";
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
  std::vector<int64_t> image_ns, odometry_ns, truth_ns;  // stamps, exact
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
    StatusOr<std::string> image_topic =
        ResolveTopic(path, "image", "image_topic", topics.image_topic, topic_types,
                     {kCompressedImage, kRawImage}, true, true);
    if (!image_topic.ok()) return image_topic.status();
    StatusOr<std::string> odometry_topic =
        ResolveTopic(path, "odometry", "odometry_topic", topics.odometry_topic, topic_types,
                     {kOdometry}, false, true);
    if (!odometry_topic.ok()) return odometry_topic.status();
    std::string truth_topic;
    if (!topics.ground_truth_topic.empty()) {
      StatusOr<std::string> t =
          ResolveTopic(path, "ground-truth", "ground_truth_topic", topics.ground_truth_topic,
                       topic_types, {kPoseStamped, kOdometry}, false, true);
      if (!t.ok()) return t.status();
      truth_topic = *t;
    }
    std::map<std::string, int64_t> last_time;  // per topic, for the order check
    uint64_t n = 0;
    for (const rosbag::MessageInstance& m : view) {
      const uint64_t index = n++;
      const std::string& topic = m.getTopic();
      if (topic != *image_topic && topic != *odometry_topic && topic != truth_topic) continue;
      const std::string where = path + ": message " + std::to_string(index) + " on " + topic;
      int64_t time_ns = 0;
      if (topic == *image_topic) {
        ImageRow row;
        if (m.getDataType() == kCompressedImage) {
          auto msg = Instantiate<sensor_msgs::CompressedImage>(m);
          if (!msg) return Status::Error(where + ": not a " + std::string(kCompressedImage));
          time_ns = Nanoseconds(msg->header.stamp, m.getTime());
        } else {
          auto msg = Instantiate<sensor_msgs::Image>(m);
          if (!msg) return Status::Error(where + ": not a " + std::string(kRawImage));
          time_ns = Nanoseconds(msg->header.stamp, m.getTime());
        }
        image_ns.push_back(time_ns);
        row.file = reference + std::to_string(index);
        row.line = static_cast<int>(std::min<uint64_t>(index, 0x7fffffff));
        d.images.push_back(row);
      } else if (topic == *odometry_topic) {
        auto msg = Instantiate<nav_msgs::Odometry>(m);
        if (!msg) return Status::Error(where + ": not a " + std::string(kOdometry));
        time_ns = Nanoseconds(msg->header.stamp, m.getTime());
        OdometryRow row;
        odometry_ns.push_back(time_ns);
        row.forward_speed_m_per_s = msg->twist.twist.linear.x;
        row.turn_rate_rad_per_s = msg->twist.twist.angular.z;
        if (!std::isfinite(row.forward_speed_m_per_s)) {
          return Status::Error(where + ": twist.twist.linear.x is not a finite number");
        }
        if (!std::isfinite(row.turn_rate_rad_per_s)) {
          return Status::Error(where + ": twist.twist.angular.z is not a finite number");
        }
        d.odometry.push_back(row);
      } else {
        geometry_msgs::Pose pose;
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
        GroundTruthRow row;
        truth_ns.push_back(time_ns);
        row.x_m = pose.position.x;
        row.y_m = pose.position.y;
        row.theta_rad =
            std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
        if (!std::isfinite(row.x_m) || !std::isfinite(row.y_m) || !std::isfinite(row.theta_rad)) {
          return Status::Error(where + ": pose is not finite");
        }
        d.ground_truth.push_back(row);
      }
      auto [it, first] = last_time.emplace(topic, time_ns);
      if (!first) {
        if (time_ns < it->second) {
          char text[160];
          std::snprintf(text, sizeof text,
                        ": header stamp goes backwards (%.9f s after %.9f s on this topic)",
                        static_cast<double>(time_ns) * 1e-9,
                        static_cast<double>(it->second) * 1e-9);
          return Status::Error(where + text);
        }
        it->second = time_ns;
      }
    }
  } catch (const std::exception& e) {
    return BagError(path, e);
  }
  // Seconds after the earliest selected message, from whole nanoseconds (a double holding
  // seconds since 1970 keeps only about 0.1 us).
  int64_t t0 = std::numeric_limits<int64_t>::max();
  for (const auto* stamps : {&image_ns, &odometry_ns, &truth_ns}) {
    if (!stamps->empty()) t0 = std::min(t0, stamps->front());
  }
  if (t0 == std::numeric_limits<int64_t>::max()) {
    return Status::Error(path + ": the bag has no image, odometry or ground-truth messages on " +
                         "the selected topics");
  }
  auto seconds = [t0](int64_t ns) { return static_cast<double>(ns - t0) / 1e9; };
  for (size_t i = 0; i < d.images.size(); ++i) d.images[i].time_s = seconds(image_ns[i]);
  for (size_t i = 0; i < d.odometry.size(); ++i) d.odometry[i].time_s = seconds(odometry_ns[i]);
  for (size_t i = 0; i < d.ground_truth.size(); ++i) {
    d.ground_truth[i].time_s = seconds(truth_ns[i]);
  }
  return d;
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
      if (msg) return DecodeCompressed(*msg, reference);
    } else if ((*m)->getDataType() == kRawImage) {
      auto msg = Instantiate<sensor_msgs::Image>(**m);
      if (msg) {
        StatusOr<cv::Mat> mat = RawToMat(*msg, reference);
        if (!mat.ok()) return mat.status();
        return GrayFromMat(*mat, reference);
      }
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
        out.extension = ExtensionOf(*msg);
        if (out.extension.empty()) {
          return Status::Error(reference + ": compressed image format '" + msg->format +
                               "' is neither PNG nor JPEG");
        }
        out.bytes = msg->data;
        return out;
      }
    } else if ((*m)->getDataType() == kRawImage) {
      auto msg = Instantiate<sensor_msgs::Image>(**m);
      if (msg) {
        StatusOr<cv::Mat> mat = RawToMat(*msg, reference);
        if (!mat.ok()) return mat.status();
        StatusOr<GrayImage> grey = GrayFromMat(*mat, reference);
        if (!grey.ok()) return grey.status();
        const cv::Mat g(grey->height, grey->width, CV_8U, grey->pixels.data());
        EncodedImage out;
        out.extension = "png";
        if (!cv::imencode(".png", g, out.bytes)) {
          return Status::Error(reference + ": cannot encode PNG");
        }
        return out;
      }
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

}  // namespace ratslam
