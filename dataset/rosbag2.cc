#include "dataset/rosbag2.h"

#include <sqlite3.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <sstream>

#include "common/file_util.h"
#include "common/text_file.h"
#include "dataset/bag_common.h"
#include "dataset/mcap.h"
#include "dataset/ros2_messages.h"
#include "dataset/ros_image.h"

namespace ratslam::dataset {
namespace fs = std::filesystem;

namespace {

constexpr const char* kCompressedImage = "sensor_msgs/msg/CompressedImage";
constexpr const char* kRawImage = "sensor_msgs/msg/Image";
constexpr const char* kOdometry = "nav_msgs/msg/Odometry";
constexpr const char* kPoseStamped = "geometry_msgs/msg/PoseStamped";
constexpr const char* kImu = "sensor_msgs/msg/Imu";

bool LooksLikeSqlite(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[16] = {};
  if (!in.read(head, sizeof head)) return false;
  return std::memcmp(head, "SQLite format 3", 16) == 0;
}

// One message handed to a reader: its place (for references and errors) and its bytes.
struct StoredMessage {
  std::string topic;
  std::string type;
  int64_t log_time_ns = 0;
  uint64_t index = 0;  // what an image reference names
  std::string where;   // "<file>: message ... on <topic>"
};

using MessageVisitor =
    std::function<Status(const StoredMessage&, const std::vector<uint8_t>& payload)>;

// One bag file: its topics (name -> type), its messages in time order, one message by index.
class Storage {
 public:
  virtual ~Storage() = default;
  const std::map<std::string, std::string>& topic_types() const { return topic_types_; }
  // Visits the messages on `selected` topics in time order.
  virtual Status ForEach(const std::set<std::string>& selected, const MessageVisitor& visit) = 0;
  virtual Status Message(uint64_t index, const MessageVisitor& visit) = 0;

 protected:
  // Records a topic's type and encoding: one type a topic, CDR only where it will be read.
  Status AddTopic(const std::string& file, const std::string& topic, const std::string& type,
                  const std::string& encoding) {
    auto [it, inserted] = topic_types_.emplace(topic, type);
    if (!inserted && it->second != type) {
      return Status::Error(file + ": topic " + topic + " carries both " + it->second + " and " +
                           type);
    }
    encodings_[topic] = encoding;
    return Status::Ok();
  }
  Status CheckEncoding(const std::string& file, const std::string& topic) const {
    auto it = encodings_.find(topic);
    if (it != encodings_.end() && it->second != "cdr") {
      return Status::Error(file + ": topic " + topic + " is serialised as '" + it->second +
                           "', not CDR (the only encoding ROS 2 bags are read in)");
    }
    return Status::Ok();
  }

  std::map<std::string, std::string> topic_types_;
  std::map<std::string, std::string> encodings_;
};

class McapStorage : public Storage {
 public:
  static StatusOr<std::unique_ptr<Storage>> Open(const std::string& path) {
    StatusOr<std::unique_ptr<McapReader>> reader = McapReader::Open(path);
    if (!reader.ok()) return reader.status();
    auto storage = std::unique_ptr<McapStorage>(new McapStorage(std::move(*reader)));
    for (const McapChannel& c : storage->reader_->channels()) {
      RATSLAM_RETURN_IF_ERROR(storage->AddTopic(path, c.topic, c.schema_name, c.message_encoding));
    }
    return std::unique_ptr<Storage>(std::move(storage));
  }

  Status ForEach(const std::set<std::string>& selected, const MessageVisitor& visit) override {
    const auto& messages = reader_->messages();
    for (uint64_t i = 0; i < messages.size(); ++i) {
      const McapChannel* channel = reader_->Channel(messages[i].channel_id);
      if (channel == nullptr || !selected.count(channel->topic)) continue;
      RATSLAM_RETURN_IF_ERROR(CheckEncoding(reader_->path(), channel->topic));
      RATSLAM_RETURN_IF_ERROR(Visit(i, *channel, visit));
    }
    return Status::Ok();
  }

  Status Message(uint64_t index, const MessageVisitor& visit) override {
    if (index >= reader_->messages().size()) {
      return Status::Error(reader_->path() + ": the file has " +
                           std::to_string(reader_->messages().size()) + " messages, not " +
                           std::to_string(index + 1));
    }
    const McapChannel* channel = reader_->Channel(reader_->messages()[index].channel_id);
    if (channel == nullptr) return Status::Error(reader_->path() + ": message without a channel");
    return Visit(index, *channel, visit);
  }

 private:
  explicit McapStorage(std::unique_ptr<McapReader> reader) : reader_(std::move(reader)) {}

  Status Visit(uint64_t index, const McapChannel& channel, const MessageVisitor& visit) {
    const McapMessage& m = reader_->messages()[index];
    StoredMessage stored;
    stored.topic = channel.topic;
    stored.type = channel.schema_name;
    stored.log_time_ns = static_cast<int64_t>(std::min<uint64_t>(m.log_time_ns, INT64_MAX));
    stored.index = index;
    stored.where = reader_->path() + ": message " + std::to_string(index) + " on " + channel.topic +
                   " (Message record at byte " + std::to_string(m.record_offset) +
                   (m.chunk >= 0 ? " of chunk " + std::to_string(m.chunk) + "'s records" : "") +
                   ")";
    StatusOr<std::vector<uint8_t>> payload = reader_->Payload(m);
    if (!payload.ok()) return payload.status();
    return visit(stored, *payload);
  }

  std::unique_ptr<McapReader> reader_;
};

// A rosbag2 sqlite3 file: tables topics(id, name, type, serialization_format, ...) and
// messages(id, topic_id, timestamp, data).
class SqliteStorage : public Storage {
 public:
  static StatusOr<std::unique_ptr<Storage>> Open(const std::string& path) {
    auto storage = std::unique_ptr<SqliteStorage>(new SqliteStorage(path));
    if (!IsRegularFile(path)) return Status::Error(path + ": not a file");
    // immutable=1: no locks, no journal files beside a bag that may sit on a read-only disk.
    std::string uri = "file:";
    for (unsigned char c : fs::absolute(path).string()) {
      if (std::isalnum(c) || std::strchr("/-_.~", c) != nullptr) {
        uri += static_cast<char>(c);
      } else {
        char hex[4];
        std::snprintf(hex, sizeof hex, "%%%02X", c);
        uri += hex;
      }
    }
    uri += "?immutable=1";
    if (sqlite3_open_v2(uri.c_str(), &storage->db_, SQLITE_OPEN_READONLY | SQLITE_OPEN_URI,
                        nullptr) != SQLITE_OK) {
      return storage->Error("cannot open");
    }
    sqlite3_db_config(storage->db_, SQLITE_DBCONFIG_DEFENSIVE, 1, nullptr);
    sqlite3_exec(storage->db_, "PRAGMA cell_size_check = ON", nullptr, nullptr, nullptr);
    sqlite3_stmt* topics = nullptr;
    if (sqlite3_prepare_v2(storage->db_, "SELECT id, name, type, serialization_format FROM topics",
                           -1, &topics, nullptr) != SQLITE_OK) {
      return storage->Error("not a rosbag2 sqlite3 file (no topics table)");
    }
    int rc = SQLITE_ROW;
    while ((rc = sqlite3_step(topics)) == SQLITE_ROW) {
      const int64_t id = sqlite3_column_int64(topics, 0);
      const std::string name = Text(topics, 1), type = Text(topics, 2);
      const std::string encoding = Text(topics, 3);
      Status s = storage->AddTopic(path, name, type, encoding);
      if (s.ok() && !storage->topic_by_id_.emplace(id, name).second) {
        s = Status::Error(path + ": topics row id " + std::to_string(id) + " twice");
      }
      if (!s.ok()) {
        sqlite3_finalize(topics);
        return s;
      }
    }
    sqlite3_finalize(topics);
    if (rc != SQLITE_DONE) return storage->Error("reading the topics table");
    return std::unique_ptr<Storage>(std::move(storage));
  }

  ~SqliteStorage() override { sqlite3_close(db_); }

  Status ForEach(const std::set<std::string>& selected, const MessageVisitor& visit) override {
    return Query("SELECT id, topic_id, timestamp, data FROM messages ORDER BY timestamp, id", -1,
                 &selected, visit);
  }

  Status Message(uint64_t index, const MessageVisitor& visit) override {
    bool found = false;
    RATSLAM_RETURN_IF_ERROR(Query("SELECT id, topic_id, timestamp, data FROM messages WHERE id = ?",
                                  static_cast<int64_t>(std::min<uint64_t>(index, INT64_MAX)),
                                  nullptr,
                                  [&](const StoredMessage& m, const std::vector<uint8_t>& payload) {
                                    found = true;
                                    return visit(m, payload);
                                  }));
    if (!found) return Status::Error(path_ + ": no message with row id " + std::to_string(index));
    return Status::Ok();
  }

 private:
  explicit SqliteStorage(std::string path) : path_(std::move(path)) {}

  static std::string Text(sqlite3_stmt* statement, int column) {
    const unsigned char* text = sqlite3_column_text(statement, column);
    return text ? reinterpret_cast<const char*>(text) : "";
  }
  Status Error(const std::string& what) const {
    return Status::Error(path_ + ": " + what +
                         " (sqlite: " + (db_ ? sqlite3_errmsg(db_) : "out of memory") + ")");
  }

  // Runs `sql` (binding `id` when it is not -1) and visits each row on a selected topic
  // (`selected` null: every row).
  Status Query(const char* sql, int64_t id, const std::set<std::string>* selected,
               const MessageVisitor& visit) {
    sqlite3_stmt* statement = nullptr;
    if (sqlite3_prepare_v2(db_, sql, -1, &statement, nullptr) != SQLITE_OK) {
      return Error("not a rosbag2 sqlite3 file (no messages table)");
    }
    if (id != -1) sqlite3_bind_int64(statement, 1, id);
    Status status = Status::Ok();
    int rc = SQLITE_ROW;
    std::vector<uint8_t> payload;
    while (status.ok() && (rc = sqlite3_step(statement)) == SQLITE_ROW) {
      const int64_t row = sqlite3_column_int64(statement, 0);
      const int64_t topic_id = sqlite3_column_int64(statement, 1);
      auto topic = topic_by_id_.find(topic_id);
      if (topic == topic_by_id_.end()) {
        status = Status::Error(path_ + ": messages row id " + std::to_string(row) + ": topic_id " +
                               std::to_string(topic_id) + " is not in the topics table");
        break;
      }
      if (selected != nullptr && !selected->count(topic->second)) continue;
      status = CheckEncoding(path_, topic->second);
      if (!status.ok()) break;
      StoredMessage m;
      m.topic = topic->second;
      m.type = topic_types_[topic->second];
      m.log_time_ns = sqlite3_column_int64(statement, 2);
      m.index = static_cast<uint64_t>(row);
      m.where = path_ + ": messages row id " + std::to_string(row) + " on " + m.topic;
      const void* blob = sqlite3_column_blob(statement, 3);
      const int bytes = sqlite3_column_bytes(statement, 3);
      payload.assign(static_cast<const uint8_t*>(blob),
                     static_cast<const uint8_t*>(blob) + (blob ? bytes : 0));
      status = visit(m, payload);
    }
    sqlite3_finalize(statement);
    if (status.ok() && rc != SQLITE_DONE && rc != SQLITE_ROW) {
      return Error("reading the messages table");
    }
    return status;
  }

  std::string path_;
  sqlite3* db_ = nullptr;
  std::map<int64_t, std::string> topic_by_id_;
};

StatusOr<std::unique_ptr<Storage>> OpenStorage(const std::string& path) {
  if (LooksLikeMcap(path)) return McapStorage::Open(path);
  if (LooksLikeSqlite(path)) return SqliteStorage::Open(path);
  return Status::Error(path + ": neither an MCAP file nor a rosbag2 sqlite3 file");
}

// The bag files a rosbag2 folder's metadata.yaml lists (rosbag2_bagfile_information:
// storage_identifier, relative_file_paths and compression_format are the keys read; the rest
// describes what the files hold).
StatusOr<std::vector<std::string>> FilesOfFolder(const std::string& folder) {
  const std::string metadata = (fs::path(folder) / "metadata.yaml").string();
  StatusOr<std::string> text = ReadRegularFile(metadata, "rosbag2 metadata", size_t{1} << 24);
  if (!text.ok()) return text.status();
  std::istringstream in(*text);
  std::string line, storage, compression;
  std::vector<std::string> files;
  bool in_list = false;
  int number = 0;
  auto value_of = [](std::string v) {
    v.erase(0, v.find_first_not_of(" \t"));
    while (!v.empty() && (v.back() == ' ' || v.back() == '\r' || v.back() == '\t')) v.pop_back();
    if (v.size() >= 2 && (v.front() == '"' || v.front() == '\'') && v.back() == v.front()) {
      v = v.substr(1, v.size() - 2);
    }
    return v;
  };
  while (std::getline(in, line)) {
    ++number;
    const size_t start = line.find_first_not_of(' ');
    if (start == std::string::npos) continue;
    const std::string trimmed = line.substr(start);
    if (in_list && trimmed.rfind("- ", 0) == 0) {
      const std::string file = value_of(trimmed.substr(2));
      if (file.empty() || fs::path(file).is_absolute() || file.find("..") != std::string::npos) {
        return Status::Error(metadata + ": line " + std::to_string(number) +
                             ": relative_file_paths entry '" + file +
                             "' is not a file name inside the folder");
      }
      files.push_back((fs::path(folder) / file).string());
      continue;
    }
    in_list = false;
    if (trimmed.rfind("storage_identifier:", 0) == 0) storage = value_of(trimmed.substr(19));
    if (trimmed.rfind("compression_format:", 0) == 0) compression = value_of(trimmed.substr(19));
    if (trimmed == "relative_file_paths:") in_list = true;
  }
  if (!compression.empty()) {
    return Status::Error(metadata + ": compression_format " + compression +
                         ": files compressed whole are not read (`ros2 bag decompress`, or record "
                         "MCAP with chunk compression)");
  }
  if (storage != "mcap" && storage != "sqlite3") {
    return Status::Error(metadata + ": storage_identifier '" + storage +
                         "' (mcap and sqlite3 are read)");
  }
  if (files.empty()) return Status::Error(metadata + ": relative_file_paths lists no file");
  for (const std::string& f : files) {
    const bool fits = storage == "mcap" ? LooksLikeMcap(f) : LooksLikeSqlite(f);
    if (!fits) {
      return Status::Error(metadata + ": " + f + " is missing or not a " + storage + " file");
    }
  }
  return files;
}

int64_t StampOrLogTime(const Ros2Time& stamp, int64_t log_time_ns) {
  return stamp.IsZero() ? log_time_ns : stamp.Nanoseconds();
}

RawImageView ViewOf(const Ros2Image& image) {
  RawImageView view;
  view.height = image.height;
  view.width = image.width;
  view.encoding = image.encoding;
  view.big_endian = image.big_endian;
  view.step = image.step;
  view.data = image.data.data();
  view.size = image.data.size();
  return view;
}

StatusOr<GrayImage> DecodeImage(const StoredMessage& m, const std::vector<uint8_t>& payload,
                                const std::string& where) {
  if (m.type == kCompressedImage) {
    StatusOr<Ros2CompressedImage> image =
        DecodeRos2CompressedImage(payload.data(), payload.size(), where);
    if (!image.ok()) return image.status();
    return GrayFromCompressedImage(image->data.data(), image->data.size(), image->format, where);
  }
  if (m.type == kRawImage) {
    StatusOr<Ros2Image> image = DecodeRos2Image(payload.data(), payload.size(), where);
    if (!image.ok()) return image.status();
    return GrayFromRawImage(ViewOf(*image), where);
  }
  return Status::Error(where + ": a " + m.type + ", not an image");
}

}  // namespace

bool LooksLikeRos2Bag(const std::string& path) {
  if (IsDirectory(path)) return IsRegularFile(fs::path(path) / "metadata.yaml");
  return IsRegularFile(path) && (LooksLikeMcap(path) || LooksLikeSqlite(path));
}

bool ParseRos2ImageReference(const std::string& reference, std::string* file, uint64_t* message) {
  const size_t hash = reference.rfind('#');
  if (hash == std::string::npos) return false;
  const std::string name = reference.substr(0, hash);
  const bool known = (name.size() > 5 && name.compare(name.size() - 5, 5, ".mcap") == 0) ||
                     (name.size() > 4 && name.compare(name.size() - 4, 4, ".db3") == 0);
  const std::string digits = reference.substr(hash + 1);
  if (!known || digits.empty() || digits.size() > 15 ||
      !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return false;
  }
  *file = name;
  *message = std::stoull(digits);
  return true;
}

StatusOr<Dataset> ReadRos2Bag(const std::string& path, const BagTopics& topics) {
  std::string error;
  if (!topics.IsValid(&error)) return Status::Error(error);
  std::vector<std::string> files;
  if (IsDirectory(path)) {
    StatusOr<std::vector<std::string>> listed = FilesOfFolder(path);
    if (!listed.ok()) return listed.status();
    files = std::move(*listed);
  } else {
    files.push_back(path);
  }
  std::vector<std::unique_ptr<Storage>> storages;
  std::map<std::string, std::string> topic_types;
  for (const std::string& file : files) {
    StatusOr<std::unique_ptr<Storage>> storage = OpenStorage(file);
    if (!storage.ok()) return storage.status();
    for (const auto& [topic, type] : (*storage)->topic_types()) {
      auto [it, inserted] = topic_types.emplace(topic, type);
      if (!inserted && it->second != type) {
        return Status::Error(file + ": topic " + topic + " carries " + type +
                             ", an earlier file of the bag " + it->second);
      }
    }
    storages.push_back(std::move(*storage));
  }
  StatusOr<SelectedBagTopics> selected_topics = SelectBagTopics(
      path, topics, topic_types,
      {{kCompressedImage, kRawImage}, {kOdometry}, {kPoseStamped, kOdometry}, {kImu}});
  if (!selected_topics.ok()) return selected_topics.status();
  const std::string& image_topic = selected_topics->image;
  const std::string& odometry_topic = selected_topics->odometry;
  const std::string& truth_topic = selected_topics->ground_truth;
  const std::string& imu_topic = selected_topics->imu;
  std::set<std::string> selected = {image_topic, odometry_topic, truth_topic, imu_topic};
  selected.erase("");

  BagDatasetBuilder builder;
  for (size_t f = 0; f < files.size(); ++f) {
    const std::string reference = fs::absolute(files[f]).string() + "#";
    RATSLAM_RETURN_IF_ERROR(storages[f]->ForEach(
        selected, [&](const StoredMessage& m, const std::vector<uint8_t>& payload) -> Status {
          const uint8_t* data = payload.data();
          const size_t size = payload.size();
          if (m.topic == image_topic) {
            StatusOr<Ros2Time> stamp = DecodeRos2Stamp(data, size, m.where);
            if (!stamp.ok()) return stamp.status();
            return builder.AddImage(StampOrLogTime(*stamp, m.log_time_ns), m.topic, m.where,
                                    reference + std::to_string(m.index), m.index);
          }
          if (m.topic == odometry_topic) {
            StatusOr<Ros2Odometry> odometry = DecodeRos2Odometry(data, size, m.where);
            if (!odometry.ok()) return odometry.status();
            return builder.AddOdometry(StampOrLogTime(odometry->stamp, m.log_time_ns), m.topic,
                                       m.where, odometry->forward_speed_m_per_s,
                                       odometry->turn_rate_rad_per_s);
          }
          if (m.topic == imu_topic) {
            StatusOr<Ros2Imu> imu = DecodeRos2Imu(data, size, m.where);
            if (!imu.ok()) return imu.status();
            const Ros2Quaternion& q = imu->orientation;
            return builder.AddCompass(StampOrLogTime(imu->stamp, m.log_time_ns), m.topic, m.where,
                                      YawOfQuaternion(q.x, q.y, q.z, q.w));
          }
          double x = 0.0, y = 0.0;
          Ros2Quaternion q;
          Ros2Time stamp;
          if (m.type == kPoseStamped) {
            StatusOr<Ros2PoseStamped> pose = DecodeRos2PoseStamped(data, size, m.where);
            if (!pose.ok()) return pose.status();
            stamp = pose->stamp;
            x = pose->x_m;
            y = pose->y_m;
            q = pose->orientation;
          } else {
            StatusOr<Ros2Odometry> pose = DecodeRos2Odometry(data, size, m.where);
            if (!pose.ok()) return pose.status();
            stamp = pose->stamp;
            x = pose->x_m;
            y = pose->y_m;
            q = pose->orientation;
          }
          return builder.AddGroundTruth(StampOrLogTime(stamp, m.log_time_ns), m.topic, m.where, x,
                                        y, YawOfQuaternion(q.x, q.y, q.z, q.w));
        }));
  }
  Dataset d;
  d.name = IsDirectory(path) ? fs::path(path).filename().string() : fs::path(path).stem().string();
  d.folder = path;
  d.image_folder = "";
  return std::move(builder).Finish(std::move(d), path);
}

class Ros2ImageReader::Impl {
 public:
  // Calls `visit` with the referenced message; call with the mutex held.
  Status Visit(const std::string& reference, const MessageVisitor& visit) {
    std::string path;
    uint64_t n = 0;
    if (!ParseRos2ImageReference(reference, &path, &n)) {
      return Status::Error(reference + ": not an image reference <file>.mcap#<n> or .db3#<n>");
    }
    std::error_code ec;
    const auto written = fs::last_write_time(path, ec);
    const auto size = ec ? 0 : fs::file_size(path, ec);
    // Reopened when another file is named or the file changed since it was indexed.
    if (path != path_ || !storage_ || written != written_ || size != size_) {
      storage_.reset();
      path_.clear();
      StatusOr<std::unique_ptr<Storage>> storage = OpenStorage(path);
      if (!storage.ok()) return storage.status();
      storage_ = std::move(*storage);
      path_ = path;
      written_ = written;
      size_ = size;
    }
    return storage_->Message(n, visit);
  }

  std::mutex mutex;

 private:
  std::string path_;
  fs::file_time_type written_{};
  uintmax_t size_ = 0;
  std::unique_ptr<Storage> storage_;
};

Ros2ImageReader::Ros2ImageReader() : impl_(std::make_unique<Impl>()) {}
Ros2ImageReader::~Ros2ImageReader() = default;

StatusOr<GrayImage> Ros2ImageReader::Load(const std::string& reference) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  StatusOr<GrayImage> out = Status::Error(reference + ": not read");
  RATSLAM_RETURN_IF_ERROR(
      impl_->Visit(reference, [&](const StoredMessage& m, const std::vector<uint8_t>& payload) {
        out = DecodeImage(m, payload, reference);
        return Status::Ok();
      }));
  return out;
}

StatusOr<EncodedImage> Ros2ImageReader::Encoded(const std::string& reference) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  StatusOr<EncodedImage> out = Status::Error(reference + ": not read");
  RATSLAM_RETURN_IF_ERROR(impl_->Visit(
      reference, [&](const StoredMessage& m, const std::vector<uint8_t>& payload) -> Status {
        if (m.type == kCompressedImage) {
          StatusOr<Ros2CompressedImage> image =
              DecodeRos2CompressedImage(payload.data(), payload.size(), reference);
          if (!image.ok()) return image.status();
          EncodedImage encoded;
          encoded.extension =
              CompressedImageExtension(image->data.data(), image->data.size(), image->format);
          if (encoded.extension.empty()) {
            return Status::Error(reference + ": compressed image format '" + image->format +
                                 "' is neither PNG nor JPEG");
          }
          encoded.bytes = std::move(image->data);
          out = std::move(encoded);
          return Status::Ok();
        }
        if (m.type == kRawImage) {
          StatusOr<Ros2Image> image = DecodeRos2Image(payload.data(), payload.size(), reference);
          if (!image.ok()) return image.status();
          out = PngFromRawImage(ViewOf(*image), reference);
          return Status::Ok();
        }
        return Status::Error(reference + ": message on " + m.topic + " is a " + m.type +
                             ", not an image");
      }));
  return out;
}

}  // namespace ratslam::dataset
