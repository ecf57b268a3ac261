// The map file's schema: one Describe(archive, object) per saved type lists its fields in file
// order, each beside its type (ratslam/state_schema.h, fusion/state_schema.h,
// fusion/wifi_sequence/state_schema.h; Pose2 in common/geometry.h, strings in
// common/byte_buffer.h). The same function encodes (EncodeArchive) and decodes (DecodeArchive), and
// a test counts each struct's members against its description, so a member added to a state struct
// but not here fails the build's tests instead of being silently dropped from saved maps.
//
// Minimum encoded sizes (the second argument of Objects) let the decoder refuse a count that the
// remaining bytes cannot hold before it allocates anything.
#ifndef RATSLAM_IO_STATE_SCHEMA_H_
#define RATSLAM_IO_STATE_SCHEMA_H_

#include "common/byte_buffer.h"
#include "fusion/state_schema.h"
#include "io/map_file.h"

namespace ratslam::io {

// The header after the magic bytes and version: which options and data set made the map. The
// resolved configuration was added in format 3.
template <typename A>
bool Describe(A& a, MapFile& m) {
  return a(m.config_fingerprint) && a(m.dataset_name) && (a.version() < 3 || a(m.config)) &&
         a.Object(m.state);
}

}  // namespace ratslam::io

#endif  // RATSLAM_IO_STATE_SCHEMA_H_
