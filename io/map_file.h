// Saving and resuming a replay: the whole pipeline state (pose cells, templates, experiences,
// links, the data-set position and everything recorded so far) in one binary file, written
// atomically (temporary file, flush to disk, rename). Loading checks the checksum, every count
// against the bytes present and every id against what it refers to (ValidateState), so a
// truncated or corrupt file is an error, never a crash or a different map.
#ifndef RATSLAM_IO_MAP_FILE_H_
#define RATSLAM_IO_MAP_FILE_H_

#include <cstdint>
#include <string>

#include "common/status.h"
#include "fusion/replay_pipeline.h"

namespace ratslam::io {

// The version written, and the oldest one read. A field added in a new version is listed in
// state_schema.h as `(a.version() < N || a(field))`, so older files load with its default.
// Version 2 is the first release with save and resume (tests/data/map-v2-*.map must load);
// version 3 adds the resolved configuration, version 4 incremental relaxation's pending work,
// version 5 the time memory of local view cells (a template's decay_time_s); its
// configurations have the PDR's orientation test (maps of format 4 resume only with it off,
// pdr.min_orientation_steadiness = 0). Version 6 adds Wi-Fi sequence loop closure (its state
// and the links it made); its configurations have the [wifi_sequence] section (maps of format 5
// and older resume with it off; fixture tests/data/map-v5-synthetic.map). Version 7 changes no
// state: its configurations have the link noise keys experience_map.link_sigma_* (the
// least_squares relaxation scheme and the g2o information), which older maps resume with at
// their defaults. Version 8 changes no state: the file ends with a CRC-32C of every byte before
// it (common/checksum.h), so a flipped byte is an error instead of a different map. Version 9
// changes no state: its configurations have the [sequence] section (image-sequence matching),
// which older maps resume with at its defaults.
inline constexpr uint32_t kMapFormatVersion = 9;
inline constexpr uint32_t kFirstChecksummedMapFormatVersion = 8;
inline constexpr uint32_t kOldestMapFormatVersion = 2;

struct MapFile {
  // The format version the file was read from (written: always the current one). Not part of
  // the schema's body: it is the header that says how to read the body.
  uint32_t format_version = 0;
  uint64_t config_fingerprint = 0;  // ConfigFingerprint of the options that made the map
  std::string dataset_name;
  // The resolved configuration that made the map (PrintConfig without comments); empty in maps
  // of format 2, which hold only the fingerprint.
  std::string config;
  fusion::ReplayPipeline::State state;
};

// Serialises to bytes / parses bytes (`source` names the file in errors).
std::string EncodeMapFile(const MapFile& map);
StatusOr<MapFile> DecodeMapFile(const std::string& bytes, const std::string& source);

Status SaveMapFile(const MapFile& map, const std::string& path);
StatusOr<MapFile> LoadMapFile(const std::string& path);

}  // namespace ratslam::io

#endif  // RATSLAM_IO_MAP_FILE_H_
