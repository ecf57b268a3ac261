// Long-term UJI library sets: four header-less CSV files fuzzed as one input, split at "%%" lines
// into rss, crd, tms and ids (fewer parts leave the later files out). Errors name a file of
// the set; accepted rows hold finite values, times at or after the epoch, and every reading an
// RSSI in [-120, 0] dBm.
#include <cmath>
#include <string>

#include "dataset/uji_long_term.h"
#include "fuzz/fuzz_support.h"

namespace ratslam::fuzz {

std::vector<std::string> FuzzSeeds() {
  const std::string rss = "100,-71,100,-45\n-80,100,-60.5,100\n100,100,-90,-91\n";
  const std::string crd = "1.5,2.25,3\n10,-4,3\n7.5,8,5\n";
  return {rss + "%%\n" + crd,
          rss + "%%\n" + crd + "%%\n736330\n2016-06-21 12:30:15\n2017,2,28,23,59,59\n%%\n1\n2\n3\n",
          rss + "%%\n" + crd + "%%\n1466512215\n1466512216\n1466512217\n",
          rss + "%%\n" + crd + "%%\n20160602155217232\n20160602155219001\n20170131090500\n"};
}

}  // namespace ratslam::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ratslam;
  const std::vector<std::string> parts = fuzz::SplitParts(data, size, "\n%%\n");
  const std::string folder = fuzz::WriteScratchFolder(
      "uji_long_term", parts, {"trn01rss.csv", "trn01crd.csv", "trn01tms.csv", "trn01ids.csv"});
  const std::string path = folder + "/trn01rss.csv";
  for (bool lenient : {false, true}) {
    dataset::UjiLongTermReport report;
    StatusOr<std::vector<dataset::LabelledScan>> scans =
        dataset::ReadUjiLongTermSet(path, lenient, &report);
    if (!scans.ok()) {
      if (scans.status().message().rfind(folder + "/trn01", 0) != 0) {
        fuzz::InvariantFailed("error does not name a file of the set: " + scans.status().message());
      }
      continue;
    }
    if (scans->size() + report.skipped_malformed != report.rows) {
      fuzz::InvariantFailed("rows read, kept and skipped do not add up");
    }
    for (const dataset::LabelledScan& s : *scans) {
      if (!std::isfinite(s.x_m) || !std::isfinite(s.y_m) || !std::isfinite(s.time_s) ||
          s.time_s < 0) {
        fuzz::InvariantFailed("accepted a row with a non-finite or negative value");
      }
      for (const WifiReading& r : s.readings) {
        if (!(r.rssi_dbm >= -120 && r.rssi_dbm <= 0)) {
          fuzz::InvariantFailed("accepted an RSSI outside [-120, 0]");
        }
      }
    }
  }
  return 0;
}
