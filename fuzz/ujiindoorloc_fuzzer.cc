// UJIIndoorLoc fingerprint CSVs: errors name the file; accepted rows hold finite values.
#include <cmath>
#include <string>

#include "dataset/ujiindoorloc.h"
#include "fuzz/fuzz_support.h"

namespace ratslam::fuzz {

std::vector<std::string> FuzzSeeds() {
  const std::string header =
      "WAP001,WAP002,WAP003,LONGITUDE,LATITUDE,FLOOR,BUILDINGID,SPACEID,RELATIVEPOSITION,USERID,"
      "PHONEID,TIMESTAMP\n";
  return {header + "100,-71,100,-7541.26,4864920.77,2,1,106,2,2,23,1371713733\n" +
          "-45,-80,100,-7540.1,4864921.5,2,1,106,2,2,23,1371713740\n"};
}

}  // namespace ratslam::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ratslam;
  const std::string path = fuzz::WriteScratchFile("uji.csv", data, size);
  for (bool lenient : {false, true}) {
    StatusOr<std::vector<dataset::LabelledScan>> scans = dataset::ReadUjiIndoorLoc(path, lenient);
    if (!scans.ok()) {
      if (scans.status().message().rfind(path, 0) != 0) {
        fuzz::InvariantFailed("error does not name the file: " + scans.status().message());
      }
      continue;
    }
    for (const dataset::LabelledScan& s : *scans) {
      if (!std::isfinite(s.x_m) || !std::isfinite(s.y_m) || !std::isfinite(s.time_s) ||
          s.time_s < 0) {
        fuzz::InvariantFailed("accepted a row with a non-finite or negative value");
      }
      for (const WifiReading& r : s.readings) {
        if (!std::isfinite(r.rssi_dbm)) fuzz::InvariantFailed("accepted a non-finite RSSI");
      }
    }
  }
  return 0;
}
