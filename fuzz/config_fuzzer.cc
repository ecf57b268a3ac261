// TOML configuration files: errors name the file; an accepted config is valid and prints to text
// that reads back to the same config.
#include <string>

#include "fuzz/fuzz_support.h"
#include "io/config.h"

namespace ratslam::fuzz {

std::vector<std::string> FuzzSeeds() {
  fusion::PipelineOptions fused;
  fused.sensors.front_end.kind = fusion::FrontEndKind::kFused;
  fused.sensors.fused.use_camera = true;
  fused.sensors.fused.use_compass = true;
  return {io::PrintConfig(fusion::PipelineOptions()), io::PrintConfig(fused, false),
          "[front_end]\nkind = \"fabmap\"\n[fabmap]\nmode = \"early\"\n[wifi_words]\nbins = 8\n",
          io::PrintLocateConfig(phone::LocateOptions())};
}

}  // namespace ratslam::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ratslam;
  const std::string text(reinterpret_cast<const char*>(data), size);
  // The same text as a wifi-map / locate configuration: the same invariants.
  StatusOr<phone::LocateOptions> locate = io::ParseLocateConfig(text, "fuzz.toml");
  if (!locate.ok() && locate.status().message().rfind("fuzz.toml", 0) != 0) {
    fuzz::InvariantFailed("error does not name the file: " + locate.status().message());
  }
  if (locate.ok()) {
    std::string invalid;
    if (!locate->IsValid(&invalid)) fuzz::InvariantFailed("accepted an invalid config: " + invalid);
    const std::string printed = io::PrintLocateConfig(*locate);
    StatusOr<phone::LocateOptions> back = io::ParseLocateConfig(printed, "printed.toml");
    if (!back.ok() || io::PrintLocateConfig(*back) != printed) {
      fuzz::InvariantFailed("locate config print/parse round trip differs");
    }
  }
  StatusOr<fusion::PipelineOptions> options = io::ParseConfig(text, "fuzz.toml");
  if (!options.ok()) {
    if (options.status().message().rfind("fuzz.toml", 0) != 0) {
      fuzz::InvariantFailed("error does not name the file: " + options.status().message());
    }
    // From a file, a text that fails may be recognised as an OpenRatSLAM INI: still an error
    // naming the file.
    const std::string path = fuzz::WriteScratchFile("config.toml", data, size);
    StatusOr<fusion::PipelineOptions> loaded = io::LoadConfigFile(path);
    if (loaded.ok() || loaded.status().message().rfind(path, 0) != 0) {
      fuzz::InvariantFailed("a file that does not parse loaded, or its error lacks the path");
    }
    return 0;
  }
  std::string error;
  if (!options->IsValid(&error)) fuzz::InvariantFailed("accepted an invalid config: " + error);
  const std::string printed = io::PrintConfig(*options);
  StatusOr<fusion::PipelineOptions> back = io::ParseConfig(printed, "printed.toml");
  if (!back.ok()) fuzz::InvariantFailed("printed config does not read: " + back.status().message());
  if (io::PrintConfig(*back) != printed) fuzz::InvariantFailed("print/parse round trip differs");
  return 0;
}
