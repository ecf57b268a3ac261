#include "fusion/io/map_file.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <type_traits>

#include "common/byte_buffer.h"
#include "common/file_util.h"
#include "common/text_file.h"
#include "fusion/io/state_schema.h"

namespace ratslam {
namespace {

constexpr char kMagic[8] = {'R', 'S', 'L', 'M', 'A', 'P', '\0', '\1'};

}  // namespace

std::string EncodeMapFile(const MapFile& map) {
  ByteWriter w;
  w.bytes().append(kMagic, sizeof kMagic);
  w.Pod(kMapFormatVersion);
  EncodeArchive archive(w, kMapFormatVersion);
  Describe(archive, const_cast<MapFile&>(map));  // the encoder only reads
  return std::move(w.bytes());
}

StatusOr<MapFile> DecodeMapFile(const std::string& bytes, const std::string& source) {
  if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0) {
    return Status::Error(source + ": not a RatSLAM map file");
  }
  // The body is read in place: a copy would double the memory a large map needs.
  ByteReader r(std::string_view(bytes).substr(sizeof kMagic), source + ": corrupt map file");
  uint32_t version = 0;
  MapFile map;
  if (!r.Pod(&version)) return Status::Error(r.error());
  if (version < kOldestMapFormatVersion || version > kMapFormatVersion) {
    return Status::Error(source + ": map file version " + std::to_string(version) +
                         " (this program reads " + std::to_string(kOldestMapFormatVersion) +
                         " to " + std::to_string(kMapFormatVersion) + ")");
  }
  DecodeArchive archive(r, version);
  if (!Describe(archive, map)) return Status::Error(r.error());
  map.format_version = version;
  if (!r.AtEnd()) return Status::Error(source + ": corrupt map file: trailing bytes");
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

}  // namespace ratslam
