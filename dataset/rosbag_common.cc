// What every build knows about bags, with or without librosbag-storage-dev.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <utility>

#include "dataset/bag_common.h"
#include "dataset/rosbag.h"

namespace ratslam::dataset {
namespace {

std::string Quoted(const std::set<std::string>& names) {
  if (names.empty()) return "none";
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

}  // namespace

StatusOr<std::string> ResolveBagTopic(const std::string& bag, const std::string& what,
                                      const std::string& key, const std::string& wanted,
                                      const std::map<std::string, std::string>& topic_types,
                                      const std::set<std::string>& types, bool try_compressed) {
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
    return Status::Error(bag + ": no topic " + name + " ([bag] " + key + "); the bag has " +
                         Quoted(all));
  }
  if (!types.count(it->second)) {
    return Status::Error(bag + ": topic " + name + " ([bag] " + key + ") carries " + it->second +
                         ", not " + what + " messages (" + Quoted(types) + ")");
  }
  return name;
}

StatusOr<SelectedBagTopics> SelectBagTopics(const std::string& bag, const BagTopics& wanted,
                                            const std::map<std::string, std::string>& topic_types,
                                            const BagMessageTypes& types) {
  SelectedBagTopics out;
  StatusOr<std::string> image = ResolveBagTopic(bag, "image", "image_topic", wanted.image_topic,
                                                topic_types, types.image, true);
  if (!image.ok()) return image.status();
  out.image = *image;
  StatusOr<std::string> odometry = ResolveBagTopic(
      bag, "odometry", "odometry_topic", wanted.odometry_topic, topic_types, types.odometry, false);
  if (!odometry.ok()) return odometry.status();
  out.odometry = *odometry;
  if (!wanted.ground_truth_topic.empty()) {
    StatusOr<std::string> t =
        ResolveBagTopic(bag, "ground-truth", "ground_truth_topic", wanted.ground_truth_topic,
                        topic_types, types.ground_truth, false);
    if (!t.ok()) return t.status();
    out.ground_truth = *t;
  }
  if (!wanted.imu_topic.empty()) {
    StatusOr<std::string> t =
        ResolveBagTopic(bag, "IMU", "imu_topic", wanted.imu_topic, topic_types, types.imu, false);
    if (!t.ok()) return t.status();
    out.imu = *t;
  }
  return out;
}

double YawOfQuaternion(double x, double y, double z, double w) {
  return std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
}

Status BagDatasetBuilder::CheckOrder(int64_t time_ns, const std::string& topic,
                                     const std::string& where) {
  auto [it, first] = last_time_ns_.emplace(topic, time_ns);
  if (first) return Status::Ok();
  if (time_ns < it->second) {
    char text[160];
    std::snprintf(text, sizeof text,
                  ": header stamp goes backwards (%.9f s after %.9f s on this topic)",
                  static_cast<double>(time_ns) * 1e-9, static_cast<double>(it->second) * 1e-9);
    return Status::Error(where + text);
  }
  it->second = time_ns;
  return Status::Ok();
}

Status BagDatasetBuilder::AddImage(int64_t time_ns, const std::string& topic,
                                   const std::string& where, std::string reference,
                                   uint64_t index) {
  RATSLAM_RETURN_IF_ERROR(CheckOrder(time_ns, topic, where));
  ImageRow row;
  row.file = std::move(reference);
  row.line = static_cast<int>(std::min<uint64_t>(index, 0x7fffffff));
  collected_.images.push_back(std::move(row));
  image_ns_.push_back(time_ns);
  return Status::Ok();
}

Status BagDatasetBuilder::AddOdometry(int64_t time_ns, const std::string& topic,
                                      const std::string& where, double forward_speed_m_per_s,
                                      double turn_rate_rad_per_s) {
  if (!std::isfinite(forward_speed_m_per_s)) {
    return Status::Error(where + ": twist.twist.linear.x is not a finite number");
  }
  if (!std::isfinite(turn_rate_rad_per_s)) {
    return Status::Error(where + ": twist.twist.angular.z is not a finite number");
  }
  RATSLAM_RETURN_IF_ERROR(CheckOrder(time_ns, topic, where));
  OdometryRow row;
  row.forward_speed_m_per_s = forward_speed_m_per_s;
  row.turn_rate_rad_per_s = turn_rate_rad_per_s;
  collected_.odometry.push_back(row);
  odometry_ns_.push_back(time_ns);
  return Status::Ok();
}

Status BagDatasetBuilder::AddGroundTruth(int64_t time_ns, const std::string& topic,
                                         const std::string& where, double x_m, double y_m,
                                         double theta_rad) {
  if (!std::isfinite(x_m) || !std::isfinite(y_m) || !std::isfinite(theta_rad)) {
    return Status::Error(where + ": pose is not finite");
  }
  RATSLAM_RETURN_IF_ERROR(CheckOrder(time_ns, topic, where));
  GroundTruthRow row;
  row.x_m = x_m;
  row.y_m = y_m;
  row.theta_rad = theta_rad;
  collected_.ground_truth.push_back(row);
  truth_ns_.push_back(time_ns);
  return Status::Ok();
}

Status BagDatasetBuilder::AddCompass(int64_t time_ns, const std::string& topic,
                                     const std::string& where, double heading_rad) {
  if (!std::isfinite(heading_rad)) return Status::Error(where + ": orientation is not finite");
  RATSLAM_RETURN_IF_ERROR(CheckOrder(time_ns, topic, where));
  CompassRow row;
  row.heading_rad = heading_rad;
  collected_.compass.push_back(row);
  compass_ns_.push_back(time_ns);
  return Status::Ok();
}

StatusOr<Dataset> BagDatasetBuilder::Finish(Dataset d, const std::string& bag) && {
  // Seconds after the earliest collected message, from whole nanoseconds (a double holding
  // seconds since 1970 keeps only about 0.1 us).
  int64_t t0 = std::numeric_limits<int64_t>::max();
  for (const auto* stamps : {&image_ns_, &odometry_ns_, &truth_ns_, &compass_ns_}) {
    if (!stamps->empty()) t0 = std::min(t0, stamps->front());
  }
  if (t0 == std::numeric_limits<int64_t>::max()) {
    return Status::Error(bag + ": the bag has no image, odometry, ground-truth or compass " +
                         "messages on the selected topics");
  }
  auto seconds = [t0](int64_t ns) { return static_cast<double>(ns - t0) / 1e9; };
  d.images = std::move(collected_.images);
  d.odometry = std::move(collected_.odometry);
  d.ground_truth = std::move(collected_.ground_truth);
  d.compass = std::move(collected_.compass);
  for (size_t i = 0; i < d.images.size(); ++i) d.images[i].time_s = seconds(image_ns_[i]);
  for (size_t i = 0; i < d.odometry.size(); ++i) d.odometry[i].time_s = seconds(odometry_ns_[i]);
  for (size_t i = 0; i < d.ground_truth.size(); ++i) {
    d.ground_truth[i].time_s = seconds(truth_ns_[i]);
  }
  for (size_t i = 0; i < d.compass.size(); ++i) d.compass[i].time_s = seconds(compass_ns_[i]);
  return d;
}

bool BagTopics::IsValid(std::string* error) const {
  const std::pair<const char*, const std::string*> topics[] = {
      {"image_topic", &image_topic},
      {"odometry_topic", &odometry_topic},
      {"ground_truth_topic", &ground_truth_topic},
      {"imu_topic", &imu_topic}};
  for (const auto& [key, topic] : topics) {
    for (char c : *topic) {
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '/' || c == '_' || c == '~')) {
        *error = std::string(key) + " '" + *topic +
                 "' has a character ROS names cannot have (letters, digits, _, / and ~)";
        return false;
      }
    }
  }
  return true;
}

std::string NormaliseRosTopic(const std::string& name) {
  std::string out = "/";
  for (char c : name) {
    if (c == '/' && out.back() == '/') continue;
    out += c;
  }
  if (out.size() > 1 && out.back() == '/') out.pop_back();
  return out;
}

bool LooksLikeRosbag(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[13] = {};
  if (!in.read(head, sizeof head)) return false;
  return std::string(head, sizeof head) == "#ROSBAG V2.0\n";
}

bool ParseBagImageReference(const std::string& path, std::string* bag, uint64_t* message) {
  const size_t hash = path.rfind('#');
  if (hash == std::string::npos || hash < 4 || path.compare(hash - 4, 4, ".bag") != 0) {
    return false;
  }
  const std::string digits = path.substr(hash + 1);
  if (digits.empty() || digits.size() > 15 ||
      !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return false;
  }
  *bag = path.substr(0, hash);
  *message = std::stoull(digits);
  return true;
}

}  // namespace ratslam::dataset
