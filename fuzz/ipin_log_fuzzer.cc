// IPIN competition phone logs: errors name the file; an accepted log becomes a data set that
// `ratslam import` can write and read back, and its barometer readings give floors.
#include <string>

#include "dataset/ipin_log.h"
#include "fuzz/dataset_round_trip.h"
#include "fuzz/fuzz_support.h"
#include "sensors/barometer.h"

namespace ratslam::fuzz {

std::vector<std::string> FuzzSeeds() {
  std::string walk = "% header\n";
  // Two seconds of walking: accelerometer at 50 Hz with steps, orientation, scans, positions.
  for (int i = 0; i < 100; ++i) {
    const double t = 0.02 * i;
    walk += "ACCE;" + std::to_string(t) + ";" + std::to_string(100 + t) + ";0.1;0.2;" +
            std::to_string(9.8 + 3.0 * ((i / 12) % 2)) + ";3\n";
    walk += "AHRS;" + std::to_string(t) + ";" + std::to_string(100 + t) +
            ";1.0;2.0;90.0;0.1;0.2;0.3;3\n";
    if (i % 10 == 0) {
      walk += "PRES;" + std::to_string(t) + ";" + std::to_string(100 + t) + ";" +
              std::to_string(976.87 - 0.05 * i) + ";3\n";
    }
  }
  walk +=
      "WIFI;0.50;100.50;net;aa:bb;2437;-60\nWIFI;0.50;100.50;net;cc:dd;5200;-71;\n"
      "WIFI;1.50;101.50;net;aa:bb;-62\nPOSI;0.0;1;49.46;11.11;0;100\nPOSI;2.0;2;49.47;11.12;1;"
      "100\n";
  return {walk, "% header\nACCE;0.10;100.10;0.1;0.2;9.8;3\nPOSI;1.0;1;49.46;11.11;0;100\n"};
}

}  // namespace ratslam::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return ratslam::fuzz::FuzzPhoneLog(
      data, size, [](const std::string& path, const ratslam::dataset::PhoneLogOptions& options) {
        // The barometer's floors from whatever PRES lines were accepted: never a crash.
        ratslam::StatusOr<ratslam::dataset::PhoneLog> log =
            ratslam::dataset::ParseIpinLog(path, options);
        if (log.ok()) (void)ratslam::sensors::EstimateFloors(log->streams.pressure);
        return ratslam::dataset::ReadIpinLog(path, options);
      });
}
