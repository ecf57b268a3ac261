// Seeds for the ROS 2 harnesses: CDR messages and a small MCAP file written here by hand after
// the CDR rules and the MCAP specification (the tests read files from independent writers; these
// only give the fuzzer valid starting points).
#ifndef RATSLAM_FUZZ_ROS2_SEEDS_H_
#define RATSLAM_FUZZ_ROS2_SEEDS_H_

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace ratslam::fuzz {

// Little-endian CDR with alignment counted from after the encapsulation header.
class CdrSeed {
 public:
  CdrSeed() : bytes_("\x00\x01\x00\x00", 4) {}
  template <typename T>
  CdrSeed& Put(T v) {
    while ((bytes_.size() - 4) % sizeof(T) != 0) bytes_ += '\0';
    char raw[sizeof(T)];
    std::memcpy(raw, &v, sizeof(T));
    bytes_.append(raw, sizeof(T));
    return *this;
  }
  CdrSeed& String(const std::string& s) {
    Put(static_cast<uint32_t>(s.size() + 1));
    bytes_ += s;
    bytes_ += '\0';
    return *this;
  }
  CdrSeed& Bytes(const std::string& s) {
    Put(static_cast<uint32_t>(s.size()));
    bytes_ += s;
    return *this;
  }
  CdrSeed& Header(int32_t sec) { return Put(sec).Put(uint32_t{500}).String("frame"); }
  CdrSeed& Doubles(int n, double v) {
    for (int i = 0; i < n; ++i) Put(v);
    return *this;
  }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

// Image (mono8 2x2), CompressedImage, Odometry, PoseStamped and Imu, in that order.
inline std::vector<std::string> Ros2SeedMessages() {
  return {
      CdrSeed()
          .Header(1)
          .Put(uint32_t{2})
          .Put(uint32_t{2})
          .String("mono8")
          .Put(uint8_t{0})
          .Put(uint32_t{2})
          .Bytes(std::string("\x01\x02\x03\x04", 4))
          .bytes(),
      CdrSeed().Header(1).String("png").Bytes("\x89PNG\r\n\x1a\n").bytes(),
      CdrSeed()
          .Header(2)
          .String("base")
          .Doubles(3, 1.0)
          .Doubles(4, 0.5)
          .Doubles(36, 0.0)
          .Doubles(6, 0.25)
          .Doubles(36, 0.0)
          .bytes(),
      CdrSeed().Header(3).Doubles(3, 2.0).Doubles(4, 0.5).bytes(),
      CdrSeed()
          .Header(4)
          .Doubles(4, 0.5)
          .Doubles(9, 0.0)
          .Doubles(3, 0.0)
          .Doubles(9, 0.0)
          .Doubles(3, 0.0)
          .Doubles(9, 0.0)
          .bytes(),
  };
}

// An MCAP file without chunks or summary: Header, one Schema and Channel per message type, one
// message each, Data End, Footer.
inline std::string Ros2SeedMcap() {
  std::string out("\x89MCAP0\r\n", 8);
  auto u16 = [](std::string* s, uint16_t v) { s->append(reinterpret_cast<char*>(&v), 2); };
  auto u32 = [](std::string* s, uint32_t v) { s->append(reinterpret_cast<char*>(&v), 4); };
  auto u64 = [](std::string* s, uint64_t v) { s->append(reinterpret_cast<char*>(&v), 8); };
  auto str = [&](std::string* s, const std::string& v) {
    u32(s, static_cast<uint32_t>(v.size()));
    *s += v;
  };
  auto record = [&](uint8_t op, const std::string& content) {
    out += static_cast<char>(op);
    u64(&out, content.size());
    out += content;
  };
  std::string header;
  str(&header, "ros2");
  str(&header, "seed");
  record(0x01, header);
  const char* types[] = {"sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage",
                         "nav_msgs/msg/Odometry", "geometry_msgs/msg/PoseStamped",
                         "sensor_msgs/msg/Imu"};
  const char* topics[] = {"/camera/image_raw", "/camera/image/compressed", "/odom", "/pose",
                          "/imu"};
  const std::vector<std::string> messages = Ros2SeedMessages();
  for (uint16_t i = 0; i < 5; ++i) {
    std::string schema, channel, message;
    u16(&schema, static_cast<uint16_t>(i + 1));
    str(&schema, types[i]);
    str(&schema, "ros2msg");
    str(&schema, "");
    record(0x03, schema);
    u16(&channel, i);
    u16(&channel, static_cast<uint16_t>(i + 1));
    str(&channel, topics[i]);
    str(&channel, "cdr");
    u32(&channel, 0);
    record(0x04, channel);
    u16(&message, i);
    u32(&message, 1);
    u64(&message, 1000000000ull * (i + 1));
    u64(&message, 1000000000ull * (i + 1));
    message += messages[i];
    record(0x05, message);
  }
  std::string data_end;
  u32(&data_end, 0);
  record(0x0F, data_end);
  std::string footer;
  u64(&footer, 0);
  u64(&footer, 0);
  u32(&footer, 0);
  record(0x02, footer);
  out.append("\x89MCAP0\r\n", 8);
  return out;
}

}  // namespace ratslam::fuzz

#endif  // RATSLAM_FUZZ_ROS2_SEEDS_H_
