// The `run` object of summary.json and evaluation.json: which build ran (version, commit, build
// type), how it was started (command line, UTC start), on what (each input with its size), with
// which seed and resolved configuration (its fingerprint).
#ifndef RATSLAM_IO_PROVENANCE_JSON_H_
#define RATSLAM_IO_PROVENANCE_JSON_H_

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "common/provenance.h"

namespace ratslam::io {

// `seed`: none when nothing in the run draws random numbers outside the configuration's own
// seeds (written as null).
nlohmann::ordered_json RunObject(const RunProvenance& provenance,
                                 const std::vector<std::string>& inputs,
                                 std::optional<uint64_t> seed, uint64_t config_fingerprint);

// A fingerprint as 16 hex digits, as summary.json writes it.
std::string FingerprintHex(uint64_t fingerprint);

}  // namespace ratslam::io

#endif  // RATSLAM_IO_PROVENANCE_JSON_H_
