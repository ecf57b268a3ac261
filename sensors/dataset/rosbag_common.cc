// What every build knows about bags, with or without librosbag-storage-dev.
#include <algorithm>
#include <cctype>
#include <fstream>
#include <utility>

#include "sensors/dataset/rosbag.h"

namespace ratslam {

bool BagTopics::IsValid(std::string* error) const {
  const std::pair<const char*, const std::string*> topics[] = {
      {"image_topic", &image_topic},
      {"odometry_topic", &odometry_topic},
      {"ground_truth_topic", &ground_truth_topic}};
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

}  // namespace ratslam
