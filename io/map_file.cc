#include "io/map_file.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <type_traits>

#include "common/byte_buffer.h"
#include "common/checksum.h"
#include "common/file_util.h"
#include "common/text_file.h"
#include "io/state_schema.h"

namespace ratslam::io {
namespace {

constexpr char kMagic[8] = {'R', 'S', 'L', 'M', 'A', 'P', '\0', '\1'};

}  // namespace

std::string EncodeMapFile(const MapFile& map) {
  ByteWriter w;
  w.bytes().append(kMagic, sizeof kMagic);
  w.Pod(kMapFormatVersion);
  EncodeArchive archive(w, kMapFormatVersion);
  Describe(archive, const_cast<MapFile&>(map));  // the encoder only reads
  AppendChecksum(&w.bytes());
  return std::move(w.bytes());
}

StatusOr<MapFile> DecodeMapFile(const std::string& bytes, const std::string& source) {
  if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0) {
    return Status::Error(source + ": not a RatSLAM map file");
  }
  // The body is read in place: a copy would double the memory a large map needs.
  std::string_view file(bytes);
  uint32_t version = 0;
  {
    ByteReader header(file.substr(sizeof kMagic), source + ": corrupt map file");
    if (!header.Pod(&version)) return Status::Error(header.error());
  }
  if (version < kOldestMapFormatVersion || version > kMapFormatVersion) {
    return Status::Error(source + ": map file version " + std::to_string(version) +
                         " (this program reads " + std::to_string(kOldestMapFormatVersion) +
                         " to " + std::to_string(kMapFormatVersion) + ")");
  }
  if (version >= kFirstChecksummedMapFormatVersion) {
    StatusOr<std::string_view> body = StripChecksum(file, source);
    if (!body.ok()) return body.status();
    file = *body;
  }
  ByteReader r(file.substr(sizeof kMagic + sizeof version), source + ": corrupt map file");
  MapFile map;
  DecodeArchive archive(r, version);
  if (!Describe(archive, map)) return Status::Error(r.error());
  map.format_version = version;
  if (!r.AtEnd()) return Status::Error(source + ": corrupt map file: trailing bytes");
  // Every reader of a map gets one that a resume would accept: a dangling id crashed `route`.
  if (Status valid = ExperienceMap::ValidateState(map.state.ratslam.experience_map); !valid.ok()) {
    return Status::Error(source + ": corrupt map file: " + valid.message());
  }
  return map;
}

Status SaveMapFile(const MapFile& map, const std::string& path) {
  return WriteFileAtomically(path, EncodeMapFile(map));
}

StatusOr<MapFile> LoadMapFile(const std::string& path) {
  StatusOr<std::string> bytes = ReadRegularFile(path, "map file", size_t{1} << 36);
  if (!bytes.ok()) return bytes.status();
  return DecodeMapFile(*bytes, path);
}

}  // namespace ratslam::io
