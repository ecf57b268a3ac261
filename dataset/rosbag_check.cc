// The record layout checked here is ROS bag format 2.0 as documented on the ROS wiki
// (Bags/Format/2.0): records of <header_len><header><data_len><data>, header fields
// <field_len><name>=<value>, little-endian integers.
#include "dataset/rosbag_check.h"

#include <bzlib.h>
#include <roslz4/lz4s.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <tuple>
#include <vector>

namespace ratslam::dataset {
namespace {
namespace fs = std::filesystem;

constexpr uint8_t kMessage = 0x02, kBagHeader = 0x03, kIndex = 0x04, kChunk = 0x05,
                  kChunkInfo = 0x06, kConnection = 0x07;
constexpr uint64_t kMagicSize = 13;
constexpr uint32_t kMaxHeader = 1u << 24;          // headers are a few hundred bytes
constexpr uint32_t kMaxChunk = uint32_t{1} << 31;  // uncompressed chunk size

uint32_t U32(const std::string& s) {
  uint32_t v = 0;
  std::memcpy(&v, s.data(), 4);  // the format is little-endian, as this machine
  return v;
}
uint64_t U64(const std::string& s) {
  uint64_t v = 0;
  std::memcpy(&v, s.data(), 8);
  return v;
}

class Checker {
 public:
  explicit Checker(std::string path) : path_(std::move(path)) {}

  Status Run() {
    std::error_code ec;
    size_ = fs::file_size(path_, ec);
    if (ec) return Status::Error(path_ + ": " + ec.message());
    in_.open(path_, std::ios::binary);
    if (!in_) return Status::Error(path_ + ": cannot open");
    // Top-level records in file order.
    std::vector<std::pair<uint64_t, uint8_t>> records;
    uint64_t index_pos = 0;
    uint32_t conn_count = 0, chunk_count = 0;
    uint64_t last_chunk = 0;
    bool in_chunk_index = false;
    for (uint64_t pos = kMagicSize; pos < size_;) {
      Record r;
      RATSLAM_RETURN_IF_ERROR(ReadRecord(pos, &r));
      const uint64_t next = r.data_pos + r.data_len;
      if (records.empty() && r.op != kBagHeader)
        return Error(pos, "the first record is not the bag header");
      if (r.op == kBagHeader) {
        if (!records.empty()) return Error(pos, "a second bag header");
        RATSLAM_RETURN_IF_ERROR(Need(r, "index_pos", 8));
        RATSLAM_RETURN_IF_ERROR(Need(r, "conn_count", 4));
        RATSLAM_RETURN_IF_ERROR(Need(r, "chunk_count", 4));
        index_pos = U64(r.fields["index_pos"]);
        conn_count = U32(r.fields["conn_count"]);
        chunk_count = U32(r.fields["chunk_count"]);
        if (index_pos == 0) {
          return Error(pos,
                       "the bag is not indexed (its recording was interrupted?): run "
                       "`rosbag reindex` on it first");
        }
      } else if (r.op == kChunk) {
        if (pos >= index_pos) return Error(pos, "a chunk after the index");
        RATSLAM_RETURN_IF_ERROR(CheckChunk(pos, r));
        last_chunk = pos;
        in_chunk_index = true;
      } else if (r.op == kIndex) {
        if (!in_chunk_index) return Error(pos, "an index record that follows no chunk");
        RATSLAM_RETURN_IF_ERROR(CheckIndex(pos, r, last_chunk));
        ++chunks_[last_chunk].index_records;
      } else if (r.op == kConnection) {
        if (pos < index_pos)
          return Error(pos, "a connection record outside chunks before the index");
        RATSLAM_RETURN_IF_ERROR(CheckConnection(pos, r));
      } else if (r.op == kChunkInfo) {
        if (pos < index_pos) return Error(pos, "a chunk info record before the index");
        RATSLAM_RETURN_IF_ERROR(CheckChunkInfo(pos, r));
      } else {
        return Error(pos, "unknown record op " + std::to_string(r.op));
      }
      if (r.op != kChunk && r.op != kIndex) in_chunk_index = false;
      records.emplace_back(pos, r.op);
      pos = next;
    }
    if (records.empty()) return Error(kMagicSize, "no records");
    // At index_pos: conn_count connection records, then chunk_count chunk infos, to the end.
    size_t i = 0;
    while (i < records.size() && records[i].first < index_pos) ++i;
    if (i == records.size() || records[i].first != index_pos) {
      return Error(index_pos, "the bag header's index_pos is not the start of a record");
    }
    for (uint32_t c = 0; c < conn_count; ++c, ++i) {
      if (i == records.size() || records[i].second != kConnection) {
        return Error(index_pos, "the index holds fewer connection records than conn_count");
      }
    }
    for (uint32_t c = 0; c < chunk_count; ++c, ++i) {
      if (i == records.size() || records[i].second != kChunkInfo) {
        return Error(index_pos, "the index holds fewer chunk info records than chunk_count");
      }
    }
    if (i != records.size()) return Error(records[i].first, "records after the index");
    for (const auto& [chunk, info] : chunk_infos_) {
      if (chunks_.at(chunk).index_records != info) {
        return Error(chunk, "a chunk followed by " +
                                std::to_string(chunks_.at(chunk).index_records) +
                                " index records where its chunk info says " + std::to_string(info));
      }
    }
    if (chunk_infos_.size() != chunks_.size())
      return Error(kMagicSize, "a chunk without a chunk info");
    for (uint32_t conn : used_) {
      if (!defined_.count(conn)) {
        return Error(kMagicSize, "connection " + std::to_string(conn) + " is used but not defined");
      }
    }
    return Status::Ok();
  }

 private:
  struct Record {
    uint8_t op = 0;
    std::map<std::string, std::string> fields;
    uint64_t data_pos = 0;
    uint32_t data_len = 0;
  };
  struct Chunk {
    std::set<uint32_t> message_offsets;  // of message records within the uncompressed chunk
    uint32_t index_records = 0;
  };

  Status Error(uint64_t offset, const std::string& what) const {
    return Status::Error(path_ + ": not a well-formed ROS bag at byte " + std::to_string(offset) +
                         ": " + what);
  }

  Status Read(uint64_t offset, uint64_t n, std::string* out) {
    if (offset > size_ || n > size_ - offset) return Error(offset, "truncated");
    out->resize(n);
    in_.seekg(static_cast<std::streamoff>(offset));
    if (!in_.read(out->data(), static_cast<std::streamsize>(n)))
      return Error(offset, "read failed");
    return Status::Ok();
  }

  // Header fields from `h` (field lengths must fit, each field is name=value).
  Status ParseFields(const std::string& h, uint64_t offset,
                     std::map<std::string, std::string>* out) {
    for (size_t p = 0; p < h.size();) {
      if (h.size() - p < 4) return Error(offset + p, "a header field's length is cut off");
      uint32_t len = 0;
      std::memcpy(&len, h.data() + p, 4);
      p += 4;
      if (len > h.size() - p) return Error(offset + p, "a header field longer than its header");
      const std::string field = h.substr(p, len);
      const size_t eq = field.find('=');
      if (eq == std::string::npos || eq == 0)
        return Error(offset + p, "a header field without name=");
      (*out)[field.substr(0, eq)] = field.substr(eq + 1);
      p += len;
    }
    return Status::Ok();
  }

  // A record at `offset` of `buffer` (or of the file when buffer is null).
  Status ReadRecordFrom(const std::string* buffer, uint64_t offset, Record* r) {
    const uint64_t limit = buffer ? buffer->size() : size_;
    auto get = [&](uint64_t at, uint64_t n, std::string* out) -> Status {
      if (at > limit || n > limit - at) return Error(at, "truncated record");
      if (!buffer) return Read(at, n, out);
      *out = buffer->substr(at, n);
      return Status::Ok();
    };
    std::string bytes;
    RATSLAM_RETURN_IF_ERROR(get(offset, 4, &bytes));
    const uint32_t header_len = U32(bytes);
    if (header_len > kMaxHeader)
      return Error(offset, "a record header of " + std::to_string(header_len) + " bytes");
    std::string header;
    RATSLAM_RETURN_IF_ERROR(get(offset + 4, header_len, &header));
    RATSLAM_RETURN_IF_ERROR(ParseFields(header, offset + 4, &r->fields));
    RATSLAM_RETURN_IF_ERROR(get(offset + 4 + header_len, 4, &bytes));
    r->data_len = U32(bytes);
    r->data_pos = offset + 8 + header_len;
    if (r->data_pos > limit || r->data_len > limit - r->data_pos) {
      return Error(offset, "record data runs past the end");
    }
    auto op = r->fields.find("op");
    if (op == r->fields.end() || op->second.size() != 1)
      return Error(offset, "a record without a one-byte op");
    r->op = static_cast<uint8_t>(op->second[0]);
    return Status::Ok();
  }
  Status ReadRecord(uint64_t offset, Record* r) { return ReadRecordFrom(nullptr, offset, r); }

  Status Need(const Record& r, const char* name, size_t size) const {
    auto it = r.fields.find(name);
    if (it == r.fields.end()) return Error(r.data_pos, std::string("missing header field ") + name);
    if (size && it->second.size() != size) {
      return Error(r.data_pos, std::string("header field ") + name + " has " +
                                   std::to_string(it->second.size()) + " bytes, not " +
                                   std::to_string(size));
    }
    return Status::Ok();
  }

  Status CheckConnectionData(uint64_t offset, const std::string& data) {
    std::map<std::string, std::string> fields;
    return ParseFields(data, offset, &fields);
  }

  Status CheckConnection(uint64_t offset, const Record& r) {
    RATSLAM_RETURN_IF_ERROR(Need(r, "conn", 4));
    RATSLAM_RETURN_IF_ERROR(Need(r, "topic", 0));
    std::string data;
    RATSLAM_RETURN_IF_ERROR(Read(r.data_pos, r.data_len, &data));
    RATSLAM_RETURN_IF_ERROR(CheckConnectionData(r.data_pos, data));
    (void)offset;
    defined_.insert(U32(r.fields.at("conn")));
    return Status::Ok();
  }

  Status CheckChunk(uint64_t offset, const Record& r) {
    RATSLAM_RETURN_IF_ERROR(Need(r, "compression", 0));
    RATSLAM_RETURN_IF_ERROR(Need(r, "size", 4));
    const std::string compression = r.fields.at("compression");
    const uint32_t size = U32(r.fields.at("size"));
    if (size > kMaxChunk) return Error(offset, "a chunk of " + std::to_string(size) + " bytes");
    std::string stored, chunk;
    RATSLAM_RETURN_IF_ERROR(Read(r.data_pos, r.data_len, &stored));
    if (compression == "none") {
      if (stored.size() != size)
        return Error(offset, "an uncompressed chunk whose size field is wrong");
      chunk = std::move(stored);
    } else if (compression == "bz2" || compression == "lz4") {
      chunk.resize(size);
      unsigned int out = size;
      const int rc =
          compression == "bz2"
              ? BZ2_bzBuffToBuffDecompress(chunk.data(), &out, stored.data(),
                                           static_cast<unsigned int>(stored.size()), 0, 0)
              : roslz4_buffToBuffDecompress(stored.data(), static_cast<unsigned int>(stored.size()),
                                            chunk.data(), &out);
      if (rc != 0 || out != size)
        return Error(offset, compression + " chunk does not decompress to its size");
    } else {
      return Error(offset, "unknown chunk compression '" + compression + "'");
    }
    Chunk& c = chunks_[offset];
    for (uint64_t p = 0; p < chunk.size();) {
      Record inner;
      RATSLAM_RETURN_IF_ERROR(ReadRecordFrom(&chunk, p, &inner)
                                  .WithContext("in the chunk at byte " + std::to_string(offset)));
      if (inner.op == kMessage) {
        RATSLAM_RETURN_IF_ERROR(Need(inner, "conn", 4));
        RATSLAM_RETURN_IF_ERROR(Need(inner, "time", 8));
        used_.insert(U32(inner.fields.at("conn")));
        c.message_offsets.insert(static_cast<uint32_t>(p));
      } else if (inner.op == kConnection) {
        RATSLAM_RETURN_IF_ERROR(Need(inner, "conn", 4));
        RATSLAM_RETURN_IF_ERROR(Need(inner, "topic", 0));
        RATSLAM_RETURN_IF_ERROR(
            CheckConnectionData(offset, chunk.substr(inner.data_pos, inner.data_len)));
        defined_.insert(U32(inner.fields.at("conn")));
      } else {
        return Error(offset, "a record of op " + std::to_string(inner.op) + " inside a chunk");
      }
      p = inner.data_pos + inner.data_len;
    }
    return Status::Ok();
  }

  Status CheckIndex(uint64_t offset, const Record& r, uint64_t chunk) {
    RATSLAM_RETURN_IF_ERROR(Need(r, "ver", 4));
    RATSLAM_RETURN_IF_ERROR(Need(r, "conn", 4));
    RATSLAM_RETURN_IF_ERROR(Need(r, "count", 4));
    if (U32(r.fields.at("ver")) != 1) return Error(offset, "index record version is not 1");
    const uint32_t count = U32(r.fields.at("count"));
    if (uint64_t{count} * 12 != r.data_len)
      return Error(offset, "index record count and length disagree");
    used_.insert(U32(r.fields.at("conn")));
    std::string data;
    RATSLAM_RETURN_IF_ERROR(Read(r.data_pos, r.data_len, &data));
    const std::set<uint32_t>& messages = chunks_.at(chunk).message_offsets;
    for (uint32_t e = 0; e < count; ++e) {
      uint32_t message = 0;
      std::memcpy(&message, data.data() + 12 * e + 8, 4);
      if (!messages.count(message)) {
        return Error(offset, "an index entry that points at no message record of its chunk");
      }
    }
    return Status::Ok();
  }

  Status CheckChunkInfo(uint64_t offset, const Record& r) {
    RATSLAM_RETURN_IF_ERROR(Need(r, "ver", 4));
    RATSLAM_RETURN_IF_ERROR(Need(r, "chunk_pos", 8));
    RATSLAM_RETURN_IF_ERROR(Need(r, "start_time", 8));
    RATSLAM_RETURN_IF_ERROR(Need(r, "end_time", 8));
    RATSLAM_RETURN_IF_ERROR(Need(r, "count", 4));
    if (U32(r.fields.at("ver")) != 1) return Error(offset, "chunk info version is not 1");
    const uint32_t count = U32(r.fields.at("count"));
    if (uint64_t{count} * 8 != r.data_len)
      return Error(offset, "chunk info count and length disagree");
    const uint64_t chunk = U64(r.fields.at("chunk_pos"));
    if (!chunks_.count(chunk)) return Error(offset, "a chunk info whose chunk_pos is no chunk");
    if (chunk_infos_.count(chunk)) return Error(offset, "two chunk infos for one chunk");
    chunk_infos_[chunk] = count;
    std::string data;
    RATSLAM_RETURN_IF_ERROR(Read(r.data_pos, r.data_len, &data));
    for (uint32_t e = 0; e < count; ++e) {
      uint32_t conn = 0;
      std::memcpy(&conn, data.data() + 8 * e, 4);
      used_.insert(conn);
    }
    return Status::Ok();
  }

  std::string path_;
  std::ifstream in_;
  uint64_t size_ = 0;
  std::map<uint64_t, Chunk> chunks_;          // by chunk record offset
  std::map<uint64_t, uint32_t> chunk_infos_;  // chunk offset -> index records it announces
  std::set<uint32_t> defined_, used_;
};

}  // namespace

Status CheckRosbagStructure(const std::string& path) {
  static std::mutex mutex;
  static std::set<std::tuple<std::string, uintmax_t, fs::file_time_type>> checked;
  std::error_code ec;
  const auto key = std::make_tuple(fs::absolute(path, ec).string(), fs::file_size(path, ec),
                                   fs::last_write_time(path, ec));
  if (ec) return Status::Error(path + ": " + ec.message());
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (checked.count(key)) return Status::Ok();
  }
  RATSLAM_RETURN_IF_ERROR(Checker(path).Run());
  std::lock_guard<std::mutex> lock(mutex);
  checked.insert(key);
  return Status::Ok();
}

}  // namespace ratslam::dataset
