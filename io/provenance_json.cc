#include "io/provenance_json.h"

#include <cstdio>

#include "common/version.h"

namespace ratslam::io {

std::string FingerprintHex(uint64_t fingerprint) {
  char text[20];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(fingerprint));
  return text;
}

nlohmann::ordered_json RunObject(const RunProvenance& provenance,
                                 const std::vector<std::string>& inputs,
                                 std::optional<uint64_t> seed, uint64_t config_fingerprint) {
  nlohmann::ordered_json run;
  run["version"] = RatslamVersion();
  run["commit"] = RatslamCommit();
  run["build_type"] = RatslamBuildType();
  run["command_line"] = provenance.command_line;
  run["started_utc"] = provenance.started_utc;
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const InputDescription& d : DescribeInputs(inputs)) {
    list.push_back({{"path", provenance.Recorded(d.path)}, {"bytes", d.bytes}, {"files", d.files}});
  }
  run["inputs"] = list;
  run["seed"] = seed ? nlohmann::ordered_json(*seed) : nlohmann::ordered_json(nullptr);
  run["config_fingerprint"] = FingerprintHex(config_fingerprint);
  return run;
}

}  // namespace ratslam::io
