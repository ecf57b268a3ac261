// Replay data sets: a manifest and its CSV streams, fuzzed as one input whose parts are separated
// by a line "%%". Errors name a file; a data set that reads is written and read back unchanged.
#include <filesystem>
#include <fstream>
#include <string>

#include "fuzz/dataset_round_trip.h"
#include "fuzz/fuzz_support.h"

namespace ratslam::fuzz {
namespace {
const char* const kFiles[] = {"manifest.toml", "odometry.csv", "images.csv",  "ground_truth.csv",
                              "wifi.csv",      "compass.csv",  "pressure.csv"};
}  // namespace

std::vector<std::string> FuzzSeeds() {
  const std::string manifest =
      "format = \"ratslam-replay\"\nformat_version = 1\nname = \"seed\"\n"
      "session_start_times_s = [0.0, 0.2]\n[streams]\nodometry = \"odometry.csv\"\n"
      "images = \"images.csv\"\nimage_folder = \"images\"\nground_truth = \"ground_truth.csv\"\n"
      "wifi = \"wifi.csv\"\ncompass = \"compass.csv\"\npressure = \"pressure.csv\"\n";
  return {manifest + "\n%%\n" +
          "time_s,forward_speed_m_per_s,turn_rate_rad_per_s\n0,0,0\n0.1,1,0.5\n0.2,1,0.1\n" +
          "\n%%\ntime_s,file\n0.05,a.png\n0.15,b.png\n" +
          "\n%%\ntime_s,x_m,y_m,theta_rad,floor\n0,0,0,0,0\n0.2,0.2,0.01,0.05,1\n" +
          "\n%%\ntime_s,bssid,rssi_dbm\n0.1,aa:bb,-60\n0.1,cc:dd,-71.5\n0.2,aa:bb,-62\n" +
          "\n%%\ntime_s,heading_rad\n0,0.1\n0.1,0.15\n" +
          "\n%%\ntime_s,pressure_hpa\n0,976.87\n0.1,976.86\n"};
}

}  // namespace ratslam::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ratslam;
  namespace fs = std::filesystem;
  const std::vector<std::string> parts = fuzz::SplitParts(data, size, "\n%%\n");
  const fs::path folder = fuzz::WriteScratchFolder(
      "dataset", parts, {std::begin(fuzz::kFiles), std::end(fuzz::kFiles)});
  StatusOr<dataset::Dataset> d = dataset::ReadDataset(folder.string());
  if (!d.ok()) {
    if (d.status().message().rfind(folder.string(), 0) != 0) {
      fuzz::InvariantFailed("error does not name a file of the data set: " + d.status().message());
    }
    return 0;
  }
  fuzz::CheckWritesAndReadsBack(*d);
  return 0;
}
