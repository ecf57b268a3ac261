// World files: errors name the file; a world that parses prints to text that parses to the same
// world.
#include <string>

#include "fuzz/fuzz_support.h"
#include "sim/world.h"

namespace ratslam::fuzz {

std::vector<std::string> FuzzSeeds() {
  std::vector<std::string> seeds;
  for (const std::string& name : sim::BuiltInWorldNames()) {
    seeds.push_back(sim::PrintWorld(*sim::BuiltInWorld(name)));
  }
  return seeds;
}

}  // namespace ratslam::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ratslam;
  const std::string text(reinterpret_cast<const char*>(data), size);
  StatusOr<sim::World> world = sim::ParseWorld(text, "fuzz.toml");
  if (!world.ok()) {
    if (world.status().message().rfind("fuzz.toml", 0) != 0) {
      fuzz::InvariantFailed("error does not name the file: " + world.status().message());
    }
    return 0;
  }
  const std::string printed = sim::PrintWorld(*world);
  StatusOr<sim::World> back = sim::ParseWorld(printed, "printed.toml");
  if (!back.ok()) fuzz::InvariantFailed("printed world does not read: " + back.status().message());
  if (sim::PrintWorld(*back) != printed) fuzz::InvariantFailed("print/parse round trip differs");
  return 0;
}
