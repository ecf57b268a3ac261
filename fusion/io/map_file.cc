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
// The version written, and the oldest one read. A field added in a new version is listed in
// state_schema.h as `(a.version() < N || a(field))`, so older files load with its default.
// Version 2 is the first release with save and resume (tests/data/map-v2-*.map must load);
// version 3 adds the resolved configuration, version 4 incremental relaxation's pending work,
// version 5 no new field: its configurations have the PDR's orientation test (maps of format 4
// resume only with it off, pdr.min_orientation_steadiness = 0).
constexpr uint32_t kVersion = 5;
constexpr uint32_t kOldestVersion = 2;

}  // namespace

std::string EncodeMapFile(const MapFile& map) {
  ByteWriter w;
  w.bytes().append(kMagic, sizeof kMagic);
  w.Pod(kVersion);
  EncodeArchive archive(w, kVersion);
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
  if (version < kOldestVersion || version > kVersion) {
    return Status::Error(source + ": map file version " + std::to_string(version) +
                         " (this program reads " + std::to_string(kOldestVersion) + " to " +
                         std::to_string(kVersion) + ")");
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
