// MCAP files (https://mcap.dev/spec, format version 0), the container of ROS 2 bags since Iron:
// an index of every message, and each message's bytes on request. Chunks may be uncompressed,
// zstd or lz4 (frame format). The data section is always read record by record (a file without
// a summary section is read the same way); a summary section, when there is one, must agree with
// it: its schemas and channels, its chunk indexes (each names a chunk the scan found, with its
// size) and its statistics (message counts, per channel too). Chunk CRCs are checked when set.
//
// Any record that does not fit is an error naming the file, the record's byte offset, its kind
// and the field; a truncated file (no footer and closing magic) is an error, never a partial
// index. Memory is bounded by the index and one decompressed chunk (at most 1 GiB).
#ifndef RATSLAM_DATASET_MCAP_H_
#define RATSLAM_DATASET_MCAP_H_

#include <cstdint>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "common/status.h"

namespace ratslam::dataset {

// Whether the file starts with MCAP's magic (0x89 "MCAP0\r\n").
bool LooksLikeMcap(const std::string& path);

struct McapChannel {
  uint16_t id = 0;
  std::string topic;
  std::string message_encoding;  // "cdr" for ROS 2
  std::string schema_name;       // e.g. "sensor_msgs/msg/Image"; empty without a schema
  std::string schema_encoding;   // e.g. "ros2msg"
};

struct McapMessage {
  uint16_t channel_id = 0;
  uint32_t sequence = 0;
  uint64_t log_time_ns = 0;
  uint64_t publish_time_ns = 0;
  uint64_t record_offset = 0;  // of the Message record: in the file, or in its chunk's records
  int64_t chunk = -1;          // which chunk (in file order) holds it; -1: the data section
  uint64_t data_offset = 0;    // of the payload: in the file, or in the decompressed chunk
  uint64_t data_size = 0;
};

class McapReader {
 public:
  // Reads the whole index. Errors name `path` and the byte offset of the record at fault.
  static StatusOr<std::unique_ptr<McapReader>> Open(const std::string& path);

  const std::string& path() const { return path_; }
  const std::string& profile() const { return profile_; }
  bool has_summary() const { return has_summary_; }
  // By id (ascending).
  const std::vector<McapChannel>& channels() const { return channels_; }
  const McapChannel* Channel(uint16_t id) const;
  // In log time order; at equal log times, in the order they are in the file.
  const std::vector<McapMessage>& messages() const { return messages_; }

  // One message's payload (decompressing its chunk, of which the last one is kept). Not
  // thread-safe.
  StatusOr<std::vector<uint8_t>> Payload(const McapMessage& message);

 private:
  struct ChunkInfo {
    uint64_t record_offset = 0;   // of the Chunk record
    uint64_t records_offset = 0;  // of its (compressed) records
    uint64_t records_size = 0;
    uint64_t uncompressed_size = 0;
    uint32_t uncompressed_crc = 0;
    std::string compression;
  };
  class Scanner;
  class Opener;

  StatusOr<const std::vector<uint8_t>*> Decompressed(int64_t chunk);

  std::string path_;
  std::ifstream file_;
  uint64_t file_size_ = 0;
  std::string profile_;
  bool has_summary_ = false;
  std::vector<McapChannel> channels_;
  std::vector<McapMessage> messages_;
  std::vector<ChunkInfo> chunks_;
  int64_t cached_chunk_ = -1;
  std::vector<uint8_t> cached_records_;
};

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_MCAP_H_
