// Record layouts from the MCAP specification, format version 0 (https://mcap.dev/spec): every
// record is an opcode byte, a uint64 content length and the content; integers are little-endian;
// strings and byte arrays carry a uint32 length (a chunk's records a uint64 one).
#include "dataset/mcap.h"

#include <lz4frame.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cstring>
#include <map>

#include "common/text_file.h"

namespace ratslam::dataset {
namespace {

constexpr uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
constexpr uint64_t kRecordHeaderBytes = 9;
constexpr uint64_t kFooterContentBytes = 20;
// A record other than a chunk or a message is small; a chunk decompresses to at most this.
constexpr uint64_t kMaxSmallRecordBytes = uint64_t{64} << 20;
constexpr uint64_t kMaxChunkBytes = uint64_t{1} << 30;

enum Opcode : uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kDataEnd = 0x0F,
};

std::string OpcodeName(uint8_t op) {
  static const char* const kNames[] = {
      "opcode 0",         "Header",     "Footer",        "Schema",         "Channel",
      "Message",          "Chunk",      "Message Index", "Chunk Index",    "Attachment",
      "Attachment Index", "Statistics", "Metadata",      "Metadata Index", "Summary Offset",
      "Data End"};
  if (op < sizeof kNames / sizeof kNames[0]) return kNames[op];
  return "opcode " + std::to_string(op);
}

// Little-endian fields of one record's content; errors name the record and the field.
class Fields {
 public:
  Fields(const uint8_t* data, uint64_t size, std::string where)
      : data_(data), size_(size), where_(std::move(where)) {}

  template <typename T>
  Status Int(const char* field, T* out) {
    RATSLAM_RETURN_IF_ERROR(Need(field, sizeof(T)));
    uint64_t v = 0;
    for (size_t k = 0; k < sizeof(T); ++k) v |= uint64_t{data_[at_ + k]} << (8 * k);
    *out = static_cast<T>(v);
    at_ += sizeof(T);
    return Status::Ok();
  }
  Status String(const char* field, std::string* out) {
    uint32_t n = 0;
    RATSLAM_RETURN_IF_ERROR(Int(field, &n));
    RATSLAM_RETURN_IF_ERROR(Need(field, n));
    out->assign(reinterpret_cast<const char*>(data_ + at_), n);
    at_ += n;
    return Status::Ok();
  }
  // A uint32-prefixed byte array or map, skipped.
  Status Skip32(const char* field) {
    uint32_t n = 0;
    RATSLAM_RETURN_IF_ERROR(Int(field, &n));
    RATSLAM_RETURN_IF_ERROR(Need(field, n));
    at_ += n;
    return Status::Ok();
  }
  Status Error(const std::string& what) const { return Status::Error(where_ + ": " + what); }
  uint64_t at() const { return at_; }
  uint64_t remaining() const { return size_ - at_; }
  const uint8_t* here() const { return data_ + at_; }

 private:
  Status Need(const char* field, uint64_t n) const {
    if (n > size_ - at_) {
      return Error(std::string("field ") + field + " runs past the end of the record (" +
                   std::to_string(n) + " bytes wanted, " + std::to_string(size_ - at_) + " left)");
    }
    return Status::Ok();
  }

  const uint8_t* data_;
  uint64_t size_;
  uint64_t at_ = 0;
  std::string where_;
};

StatusOr<std::vector<uint8_t>> Decompress(const std::string& compression, const uint8_t* data,
                                          uint64_t size, uint64_t uncompressed_size,
                                          const std::string& where) {
  if (uncompressed_size > kMaxChunkBytes) {
    return Status::Error(where + ": uncompressed_size " + std::to_string(uncompressed_size) +
                         " is over the 1 GiB a chunk may hold here");
  }
  // Sizes the data cannot hold are refused before the output is allocated: a zstd frame that
  // states another size, an lz4 frame larger than LZ4's greatest ratio (255:1) allows.
  if (compression == "zstd") {
    const unsigned long long stated = ZSTD_getFrameContentSize(data, size);
    if (stated == ZSTD_CONTENTSIZE_ERROR) return Status::Error(where + ": not a zstd frame");
    if (stated != ZSTD_CONTENTSIZE_UNKNOWN && stated != uncompressed_size) {
      return Status::Error(where + ": zstd frame holds " + std::to_string(stated) +
                           " bytes, uncompressed_size says " + std::to_string(uncompressed_size));
    }
  }
  if (compression == "lz4" && uncompressed_size / 255 > size + 64) {
    return Status::Error(where + ": uncompressed_size " + std::to_string(uncompressed_size) +
                         " is more than an lz4 frame of " + std::to_string(size) +
                         " bytes can hold");
  }
  std::vector<uint8_t> out(uncompressed_size);
  if (compression.empty()) {
    if (size != uncompressed_size) {
      return Status::Error(where + ": uncompressed chunk of " + std::to_string(size) +
                           " bytes, uncompressed_size says " + std::to_string(uncompressed_size));
    }
    if (size > 0) std::memcpy(out.data(), data, size);
    return out;
  }
  if (compression == "zstd") {
    const size_t got = ZSTD_decompress(out.data(), out.size(), data, size);
    if (ZSTD_isError(got)) {
      return Status::Error(where + ": zstd: " + ZSTD_getErrorName(got));
    }
    if (got != uncompressed_size) {
      return Status::Error(where + ": zstd data holds " + std::to_string(got) +
                           " bytes, uncompressed_size says " + std::to_string(uncompressed_size));
    }
    return out;
  }
  if (compression == "lz4") {
    LZ4F_dctx* context = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&context, LZ4F_VERSION))) {
      return Status::Error(where + ": lz4: no decompression context");
    }
    size_t in = 0, produced = 0, hint = 1;
    while (hint != 0) {
      size_t out_size = out.size() - produced;
      size_t in_size = size - in;
      if (in_size == 0) break;
      hint =
          LZ4F_decompress(context, out.data() + produced, &out_size, data + in, &in_size, nullptr);
      if (LZ4F_isError(hint)) {
        LZ4F_freeDecompressionContext(context);
        return Status::Error(where + ": lz4: " + LZ4F_getErrorName(hint));
      }
      in += in_size;
      produced += out_size;
      if (in_size == 0 && out_size == 0) break;  // no progress: the output is full
    }
    LZ4F_freeDecompressionContext(context);
    if (hint != 0) return Status::Error(where + ": lz4 frame ends early");
    if (in != size || produced != uncompressed_size) {
      return Status::Error(where + ": lz4 frame holds " + std::to_string(produced) + " bytes in " +
                           std::to_string(in) + " of " + std::to_string(size) +
                           ", uncompressed_size says " + std::to_string(uncompressed_size));
    }
    return out;
  }
  return Status::Error(where + ": compression '" + compression +
                       "' is not read (zstd, lz4 or none)");
}

}  // namespace

bool LooksLikeMcap(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[8] = {};
  if (!in.read(head, sizeof head)) return false;
  return std::memcmp(head, kMagic, sizeof kMagic) == 0;
}

// Reads records into the reader's index: the schemas and channels it has seen, the messages and
// chunks. The same code reads the file's data section and each chunk's records.
class McapReader::Scanner {
 public:
  explicit Scanner(McapReader* reader) : reader_(reader) {}

  // One record whose content is in memory. `chunk` -1: the data section (then `content_offset`
  // is the content's file offset) or a chunk's index.
  Status Record(uint8_t op, const uint8_t* content, uint64_t size, uint64_t record_offset,
                uint64_t content_offset, int64_t chunk, const std::string& where) {
    Fields f(content, size, where);
    switch (op) {
      case kSchema: {
        uint16_t id = 0;
        std::string name, encoding;
        RATSLAM_RETURN_IF_ERROR(f.Int("id", &id));
        RATSLAM_RETURN_IF_ERROR(f.String("name", &name));
        RATSLAM_RETURN_IF_ERROR(f.String("encoding", &encoding));
        RATSLAM_RETURN_IF_ERROR(f.Skip32("data"));
        if (id == 0) return f.Error("schema id 0 is reserved for \"no schema\"");
        auto [it, inserted] = schemas_.emplace(id, std::make_pair(name, encoding));
        if (!inserted && it->second != std::make_pair(name, encoding)) {
          return f.Error("schema " + std::to_string(id) + " redefined as " + name);
        }
        return Status::Ok();
      }
      case kChannel: {
        McapChannel c;
        uint16_t schema_id = 0;
        RATSLAM_RETURN_IF_ERROR(f.Int("id", &c.id));
        RATSLAM_RETURN_IF_ERROR(f.Int("schema_id", &schema_id));
        RATSLAM_RETURN_IF_ERROR(f.String("topic", &c.topic));
        RATSLAM_RETURN_IF_ERROR(f.String("message_encoding", &c.message_encoding));
        RATSLAM_RETURN_IF_ERROR(f.Skip32("metadata"));
        if (schema_id != 0) {
          auto schema = schemas_.find(schema_id);
          if (schema == schemas_.end()) {
            return f.Error("channel " + std::to_string(c.id) + " (" + c.topic + ") names schema " +
                           std::to_string(schema_id) +
                           ", which no Schema record before it defines");
          }
          c.schema_name = schema->second.first;
          c.schema_encoding = schema->second.second;
        }
        auto [it, inserted] = channels_.emplace(c.id, c);
        if (!inserted && (it->second.topic != c.topic || it->second.schema_name != c.schema_name ||
                          it->second.message_encoding != c.message_encoding)) {
          return f.Error("channel " + std::to_string(c.id) + " redefined (" + it->second.topic +
                         ", then " + c.topic + ")");
        }
        return Status::Ok();
      }
      case kMessage: {
        McapMessage m;
        RATSLAM_RETURN_IF_ERROR(f.Int("channel_id", &m.channel_id));
        RATSLAM_RETURN_IF_ERROR(f.Int("sequence", &m.sequence));
        RATSLAM_RETURN_IF_ERROR(f.Int("log_time", &m.log_time_ns));
        RATSLAM_RETURN_IF_ERROR(f.Int("publish_time", &m.publish_time_ns));
        if (!channels_.count(m.channel_id)) {
          return f.Error("message on channel " + std::to_string(m.channel_id) +
                         ", which no Channel record before it defines");
        }
        m.record_offset = record_offset;
        m.chunk = chunk;
        m.data_offset = content_offset + f.at();
        m.data_size = f.remaining();
        reader_->messages_.push_back(m);
        return Status::Ok();
      }
      default:
        if (chunk >= 0) return f.Error("a chunk may hold Schema, Channel and Message records only");
        return Status::Ok();  // other records carry nothing the data set needs
    }
  }

  // The records of a decompressed chunk.
  Status ChunkRecords(const std::vector<uint8_t>& records, int64_t chunk,
                      const std::string& where) {
    uint64_t at = 0;
    while (at < records.size()) {
      const std::string here = where + ", byte " + std::to_string(at) + " of its records";
      if (records.size() - at < kRecordHeaderBytes) {
        return Status::Error(here + ": record header runs past the end of the chunk");
      }
      const uint8_t op = records[at];
      uint64_t length = 0;
      for (int k = 0; k < 8; ++k) length |= uint64_t{records[at + 1 + k]} << (8 * k);
      if (length > records.size() - at - kRecordHeaderBytes) {
        return Status::Error(here + " (" + OpcodeName(op) + " record): length " +
                             std::to_string(length) + " runs past the end of the chunk");
      }
      RATSLAM_RETURN_IF_ERROR(Record(op, records.data() + at + kRecordHeaderBytes, length, at,
                                     at + kRecordHeaderBytes, chunk,
                                     here + " (" + OpcodeName(op) + " record)"));
      at += kRecordHeaderBytes + length;
    }
    return Status::Ok();
  }

  std::map<uint16_t, std::pair<std::string, std::string>> schemas_;
  std::map<uint16_t, McapChannel> channels_;

 private:
  McapReader* reader_;
};

const McapChannel* McapReader::Channel(uint16_t id) const {
  auto it = std::lower_bound(channels_.begin(), channels_.end(), id,
                             [](const McapChannel& c, uint16_t i) { return c.id < i; });
  return it != channels_.end() && it->id == id ? &*it : nullptr;
}

// Open's work: the file's footer, then its data section and its summary section walked record
// by record into the reader's index. Errors name the file and the byte offset of the record.
class McapReader::Opener {
 public:
  explicit Opener(McapReader* reader)
      : reader_(reader), path_(reader->path_), file_(reader->file_), scanner_(reader) {}

  Status Run() {
    file_.seekg(0, std::ios::end);
    file_size_ = static_cast<uint64_t>(file_.tellg());
    reader_->file_size_ = file_size_;
    uint8_t magic[8];
    if (file_size_ < 8 || !ReadAt(0, 8, magic) || std::memcmp(magic, kMagic, 8) != 0) {
      return Status::Error(path_ + ": not an MCAP file (it does not start with MCAP's magic)");
    }
    RATSLAM_RETURN_IF_ERROR(ReadFooter());
    const uint64_t data_end = summary_start_ != 0 ? summary_start_ : footer_offset_;
    StatusOr<uint64_t> scanned =
        Walk(8, data_end, kDataEnd,
             [this](uint8_t op, uint64_t at, uint64_t length, const std::string& where) {
               return DataRecord(op, at, length, where);
             });
    if (!scanned.ok()) return scanned.status();
    if (first_) return ErrorAt(8, "no Header record");
    if (summary_start_ != 0) RATSLAM_RETURN_IF_ERROR(ReadSummary());
    for (const auto& [id, channel] : scanner_.channels_) reader_->channels_.push_back(channel);
    std::stable_sort(
        reader_->messages_.begin(), reader_->messages_.end(),
        [](const McapMessage& a, const McapMessage& b) { return a.log_time_ns < b.log_time_ns; });
    return Status::Ok();
  }

 private:
  bool ReadAt(uint64_t offset, uint64_t n, uint8_t* out) {
    file_.clear();
    file_.seekg(static_cast<std::streamoff>(offset));
    return static_cast<bool>(
        file_.read(reinterpret_cast<char*>(out), static_cast<std::streamsize>(n)));
  }

  Status ErrorAt(uint64_t offset, const std::string& what) const {
    return Status::Error(path_ + ": byte " + std::to_string(offset) + ": " + what);
  }

  // The footer and the closing magic end every complete file.
  Status ReadFooter() {
    footer_offset_ = file_size_ - 8 - kRecordHeaderBytes - kFooterContentBytes;
    uint8_t tail[kRecordHeaderBytes + kFooterContentBytes + 8];
    if (file_size_ < 8 + sizeof tail || !ReadAt(footer_offset_, sizeof tail, tail) ||
        std::memcmp(tail + kRecordHeaderBytes + kFooterContentBytes, kMagic, 8) != 0 ||
        tail[0] != kFooter) {
      return Status::Error(
          path_ +
          ": truncated MCAP file (it does not end with a Footer record and the "
          "magic; a recording that was cut off can be repaired with `mcap recover`)");
    }
    Fields footer(tail + kRecordHeaderBytes, kFooterContentBytes,
                  path_ + ": byte " + std::to_string(footer_offset_) + " (Footer record)");
    uint64_t footer_length = 0;
    for (int k = 0; k < 8; ++k) footer_length |= uint64_t{tail[1 + k]} << (8 * k);
    RATSLAM_RETURN_IF_ERROR(footer.Int("summary_start", &summary_start_));
    RATSLAM_RETURN_IF_ERROR(footer.Int("summary_offset_start", &summary_offset_start_));
    if (footer_length != kFooterContentBytes) {
      return ErrorAt(footer_offset_,
                     "Footer record of " + std::to_string(footer_length) + " bytes (20 expected)");
    }
    if (summary_start_ != 0 && (summary_start_ < 8 || summary_start_ > footer_offset_)) {
      return ErrorAt(footer_offset_, "Footer's summary_start " + std::to_string(summary_start_) +
                                         " lies outside the file's records");
    }
    if (summary_offset_start_ != 0 &&
        (summary_offset_start_ < summary_start_ || summary_offset_start_ > footer_offset_)) {
      return ErrorAt(footer_offset_, "Footer's summary_offset_start " +
                                         std::to_string(summary_offset_start_) +
                                         " lies outside the summary section");
    }
    return Status::Ok();
  }

  // Walks the records in [begin, end); `visit` sees each (op, offset, content length, where).
  // Stops after `stop_op` when given.
  template <typename Visit>
  StatusOr<uint64_t> Walk(uint64_t begin, uint64_t end, int stop_op, Visit&& visit) {
    uint64_t at = begin;
    while (at < end) {
      uint8_t header[kRecordHeaderBytes];
      if (end - at < kRecordHeaderBytes || !ReadAt(at, kRecordHeaderBytes, header)) {
        return ErrorAt(at, "record header runs past the end of its section");
      }
      const uint8_t op = header[0];
      uint64_t length = 0;
      for (int k = 0; k < 8; ++k) length |= uint64_t{header[1 + k]} << (8 * k);
      const std::string where =
          path_ + ": byte " + std::to_string(at) + " (" + OpcodeName(op) + " record)";
      if (length > end - at - kRecordHeaderBytes) {
        return Status::Error(where + ": length " + std::to_string(length) +
                             " runs past the end of its section");
      }
      RATSLAM_RETURN_IF_ERROR(visit(op, at, length, where));
      at += kRecordHeaderBytes + length;
      if (op == stop_op) return at;
    }
    return at;
  }

  // The content of the record at `at` into content_, refused over `limit` bytes.
  Status ReadContent(uint64_t at, uint64_t length, uint64_t limit, const std::string& where) {
    if (length > limit) {
      return Status::Error(where + ": " + std::to_string(length) + " bytes is over the " +
                           std::to_string(limit) + " such a record may have here");
    }
    content_.resize(length);
    if (length > 0 && !ReadAt(at + kRecordHeaderBytes, length, content_.data())) {
      return Status::Error(where + ": cannot read its content");
    }
    return Status::Ok();
  }

  // One record of the data section.
  Status DataRecord(uint8_t op, uint64_t at, uint64_t length, const std::string& where) {
    if (first_ != (op == kHeader)) {
      return Status::Error(
          where + (first_ ? ": the first record must be a Header" : ": a second Header record"));
    }
    first_ = false;
    if (op == kHeader) {
      RATSLAM_RETURN_IF_ERROR(ReadContent(at, length, kMaxSmallRecordBytes, where));
      Fields f(content_.data(), content_.size(), where);
      return f.String("profile", &reader_->profile_);
    }
    if (op == kMessage) {
      // Only the fixed fields: the payload stays in the file until asked for.
      constexpr uint64_t kFixed = 2 + 4 + 8 + 8;
      if (length < kFixed) {
        return Status::Error(where + ": " + std::to_string(length) +
                             " bytes, fewer than a message's fixed fields");
      }
      RATSLAM_RETURN_IF_ERROR(ReadContent(at, kFixed, kFixed, where));
      const size_t before = reader_->messages_.size();
      RATSLAM_RETURN_IF_ERROR(
          scanner_.Record(op, content_.data(), kFixed, at, at + kRecordHeaderBytes, -1, where));
      reader_->messages_[before].data_size = length - kFixed;
      return Status::Ok();
    }
    if (op == kChunk) return ChunkRecord(at, length, where);
    if (op == kSchema || op == kChannel) {
      RATSLAM_RETURN_IF_ERROR(ReadContent(at, length, kMaxSmallRecordBytes, where));
      return scanner_.Record(op, content_.data(), content_.size(), at, at + kRecordHeaderBytes, -1,
                             where);
    }
    if (op == kFooter) return Status::Error(where + ": a Footer inside the data section");
    return Status::Ok();
  }

  // A Chunk of the data section: decompressed, checked and its records scanned.
  Status ChunkRecord(uint64_t at, uint64_t length, const std::string& where) {
    RATSLAM_RETURN_IF_ERROR(ReadContent(at, length, length, where));
    Fields f(content_.data(), content_.size(), where);
    ChunkInfo chunk;
    uint64_t start_time = 0, end_time = 0;
    RATSLAM_RETURN_IF_ERROR(f.Int("message_start_time", &start_time));
    RATSLAM_RETURN_IF_ERROR(f.Int("message_end_time", &end_time));
    RATSLAM_RETURN_IF_ERROR(f.Int("uncompressed_size", &chunk.uncompressed_size));
    RATSLAM_RETURN_IF_ERROR(f.Int("uncompressed_crc", &chunk.uncompressed_crc));
    RATSLAM_RETURN_IF_ERROR(f.String("compression", &chunk.compression));
    RATSLAM_RETURN_IF_ERROR(f.Int("records length", &chunk.records_size));
    if (chunk.records_size != f.remaining()) {
      return Status::Error(where + ": records length " + std::to_string(chunk.records_size) +
                           " but " + std::to_string(f.remaining()) + " bytes follow");
    }
    chunk.record_offset = at;
    chunk.records_offset = at + kRecordHeaderBytes + f.at();
    StatusOr<std::vector<uint8_t>> records =
        Decompress(chunk.compression, f.here(), chunk.records_size, chunk.uncompressed_size, where);
    if (!records.ok()) return records.status();
    if (chunk.uncompressed_crc != 0) {
      const uint32_t crc = static_cast<uint32_t>(
          crc32(crc32(0, nullptr, 0), records->data(), static_cast<uInt>(records->size())));
      if (crc != chunk.uncompressed_crc) {
        return Status::Error(where + ": uncompressed_crc does not match its records");
      }
    }
    const int64_t index = static_cast<int64_t>(reader_->chunks_.size());
    reader_->chunks_.push_back(chunk);
    return scanner_.ChunkRecords(*records, index, where);
  }

  // The summary section: its schemas, channels, chunk indexes and statistics must agree with
  // the data section.
  Status ReadSummary() {
    reader_->has_summary_ = true;
    const uint64_t summary_end =
        summary_offset_start_ != 0 ? summary_offset_start_ : footer_offset_;
    for (const ChunkInfo& c : reader_->chunks_) chunk_at_[c.record_offset] = &c;
    Scanner summary(reader_);
    summary.schemas_ = scanner_.schemas_;  // a summary may repeat channels without their schemas
    messages_before_ = reader_->messages_.size();
    StatusOr<uint64_t> checked =
        Walk(summary_start_, summary_end, -1,
             [&](uint8_t op, uint64_t at, uint64_t length, const std::string& where) {
               return SummaryRecord(summary, op, at, length, where);
             });
    if (!checked.ok()) return checked.status();
    for (const auto& [id, channel] : summary.channels_) {
      auto [seen, inserted] = scanner_.channels_.emplace(id, channel);
      if (!inserted && (seen->second.topic != channel.topic ||
                        seen->second.schema_name != channel.schema_name)) {
        return Status::Error(path_ + ": summary section: channel " + std::to_string(id) + " is " +
                             channel.topic + " there and " + seen->second.topic +
                             " in the data section");
      }
    }
    return Status::Ok();
  }

  Status SummaryRecord(Scanner& summary, uint8_t op, uint64_t at, uint64_t length,
                       const std::string& where) {
    if (op == kMessage || op == kChunk || op == kHeader || op == kDataEnd) {
      return Status::Error(where + ": not a record the summary section may hold");
    }
    if (op != kSchema && op != kChannel && op != kChunkIndex && op != kStatistics) {
      return Status::Ok();
    }
    RATSLAM_RETURN_IF_ERROR(ReadContent(at, length, kMaxSmallRecordBytes, where));
    if (op == kSchema || op == kChannel) {
      RATSLAM_RETURN_IF_ERROR(summary.Record(op, content_.data(), content_.size(), at,
                                             at + kRecordHeaderBytes, -1, where));
      return Status::Ok();
    }
    Fields f(content_.data(), content_.size(), where);
    return op == kChunkIndex ? CheckChunkIndex(f, where) : CheckStatistics(f, where);
  }

  Status CheckChunkIndex(Fields& f, const std::string& where) const {
    uint64_t start = 0, end = 0, offset = 0, length_field = 0, index_length = 0;
    uint64_t compressed = 0, uncompressed = 0;
    std::string compression;
    RATSLAM_RETURN_IF_ERROR(f.Int("message_start_time", &start));
    RATSLAM_RETURN_IF_ERROR(f.Int("message_end_time", &end));
    RATSLAM_RETURN_IF_ERROR(f.Int("chunk_start_offset", &offset));
    RATSLAM_RETURN_IF_ERROR(f.Int("chunk_length", &length_field));
    RATSLAM_RETURN_IF_ERROR(f.Skip32("message_index_offsets"));
    RATSLAM_RETURN_IF_ERROR(f.Int("message_index_length", &index_length));
    RATSLAM_RETURN_IF_ERROR(f.String("compression", &compression));
    RATSLAM_RETURN_IF_ERROR(f.Int("compressed_size", &compressed));
    RATSLAM_RETURN_IF_ERROR(f.Int("uncompressed_size", &uncompressed));
    auto chunk = chunk_at_.find(offset);
    if (chunk == chunk_at_.end()) {
      return Status::Error(where + ": chunk_start_offset " + std::to_string(offset) +
                           " is not where a chunk starts");
    }
    if (compressed != chunk->second->records_size ||
        uncompressed != chunk->second->uncompressed_size ||
        compression != chunk->second->compression) {
      return Status::Error(where + ": the chunk at byte " + std::to_string(offset) +
                           " has other sizes or compression than its index says");
    }
    return Status::Ok();
  }

  Status CheckStatistics(Fields& f, const std::string& where) const {
    uint64_t message_count = 0, start = 0, end = 0;
    uint16_t schema_count = 0;
    uint32_t channel_count = 0, attachment_count = 0, metadata_count = 0, chunk_count = 0;
    uint32_t map_bytes = 0;
    RATSLAM_RETURN_IF_ERROR(f.Int("message_count", &message_count));
    RATSLAM_RETURN_IF_ERROR(f.Int("schema_count", &schema_count));
    RATSLAM_RETURN_IF_ERROR(f.Int("channel_count", &channel_count));
    RATSLAM_RETURN_IF_ERROR(f.Int("attachment_count", &attachment_count));
    RATSLAM_RETURN_IF_ERROR(f.Int("metadata_count", &metadata_count));
    RATSLAM_RETURN_IF_ERROR(f.Int("chunk_count", &chunk_count));
    RATSLAM_RETURN_IF_ERROR(f.Int("message_start_time", &start));
    RATSLAM_RETURN_IF_ERROR(f.Int("message_end_time", &end));
    RATSLAM_RETURN_IF_ERROR(f.Int("channel_message_counts", &map_bytes));
    if (message_count != messages_before_) {
      return Status::Error(where + ": message_count " + std::to_string(message_count) +
                           " but the data section holds " + std::to_string(messages_before_));
    }
    if (chunk_count != reader_->chunks_.size()) {
      return Status::Error(where + ": chunk_count " + std::to_string(chunk_count) +
                           " but the data section holds " +
                           std::to_string(reader_->chunks_.size()));
    }
    if (map_bytes != f.remaining() || map_bytes % 10 != 0) {
      return Status::Error(where + ": channel_message_counts of " + std::to_string(map_bytes) +
                           " bytes does not fit the record");
    }
    std::map<uint16_t, uint64_t> counted;
    for (const McapMessage& m : reader_->messages_) ++counted[m.channel_id];
    while (f.remaining() > 0) {
      uint16_t id = 0;
      uint64_t count = 0;
      RATSLAM_RETURN_IF_ERROR(f.Int("channel_message_counts channel", &id));
      RATSLAM_RETURN_IF_ERROR(f.Int("channel_message_counts count", &count));
      const uint64_t seen = counted.count(id) ? counted[id] : 0;
      if (count != seen) {
        return Status::Error(where + ": channel " + std::to_string(id) + " has " +
                             std::to_string(count) + " messages by the statistics, " +
                             std::to_string(seen) + " in the data section");
      }
    }
    return Status::Ok();
  }

  McapReader* reader_;
  const std::string& path_;
  std::ifstream& file_;
  uint64_t file_size_ = 0;
  uint64_t footer_offset_ = 0, summary_start_ = 0, summary_offset_start_ = 0;
  Scanner scanner_;                                // the data section's schemas and channels
  std::vector<uint8_t> content_;                   // the record being read
  bool first_ = true;                              // no record of the data section read yet
  std::map<uint64_t, const ChunkInfo*> chunk_at_;  // by the Chunk record's offset
  size_t messages_before_ = 0;                     // messages in the data section
};

StatusOr<std::unique_ptr<McapReader>> McapReader::Open(const std::string& path) {
  auto reader = std::unique_ptr<McapReader>(new McapReader());
  reader->path_ = path;
  RATSLAM_RETURN_IF_ERROR(OpenRegularFile(path, "MCAP file", &reader->file_));
  RATSLAM_RETURN_IF_ERROR(Opener(reader.get()).Run());
  return reader;
}

StatusOr<const std::vector<uint8_t>*> McapReader::Decompressed(int64_t chunk) {
  if (chunk == cached_chunk_) return &cached_records_;
  const ChunkInfo& c = chunks_[static_cast<size_t>(chunk)];
  const std::string where = path_ + ": byte " + std::to_string(c.record_offset) + " (Chunk record)";
  std::vector<uint8_t> compressed(c.records_size);
  file_.clear();
  file_.seekg(static_cast<std::streamoff>(c.records_offset));
  if (!file_.read(reinterpret_cast<char*>(compressed.data()),
                  static_cast<std::streamsize>(compressed.size()))) {
    return Status::Error(where + ": cannot read it again (the file changed?)");
  }
  StatusOr<std::vector<uint8_t>> records =
      Decompress(c.compression, compressed.data(), compressed.size(), c.uncompressed_size, where);
  if (!records.ok()) return records.status();
  cached_records_ = std::move(*records);
  cached_chunk_ = chunk;
  return &cached_records_;
}

StatusOr<std::vector<uint8_t>> McapReader::Payload(const McapMessage& m) {
  if (m.chunk < 0) {
    if (m.data_offset > file_size_ || m.data_size > file_size_ - m.data_offset) {
      return Status::Error(path_ + ": message at byte " + std::to_string(m.record_offset) +
                           " runs past the end of the file");
    }
    std::vector<uint8_t> out(m.data_size);
    file_.clear();
    file_.seekg(static_cast<std::streamoff>(m.data_offset));
    if (m.data_size > 0 && !file_.read(reinterpret_cast<char*>(out.data()),
                                       static_cast<std::streamsize>(out.size()))) {
      return Status::Error(path_ + ": message at byte " + std::to_string(m.record_offset) +
                           ": cannot read its data");
    }
    return out;
  }
  if (static_cast<size_t>(m.chunk) >= chunks_.size()) {
    return Status::Error(path_ + ": no chunk " + std::to_string(m.chunk));
  }
  StatusOr<const std::vector<uint8_t>*> records = Decompressed(m.chunk);
  if (!records.ok()) return records.status();
  const std::vector<uint8_t>& r = **records;
  if (m.data_offset > r.size() || m.data_size > r.size() - m.data_offset) {
    return Status::Error(path_ + ": message outside its chunk");
  }
  return std::vector<uint8_t>(r.begin() + static_cast<ptrdiff_t>(m.data_offset),
                              r.begin() + static_cast<ptrdiff_t>(m.data_offset + m.data_size));
}

}  // namespace ratslam::dataset
