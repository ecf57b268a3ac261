// Microsoft Indoor Location Competition walks: errors name the file; an accepted log becomes a data
// set that `ratslam import` can write and read back.
#include <string>

#include "dataset/msft_log.h"
#include "fuzz/dataset_round_trip.h"
#include "fuzz/fuzz_support.h"

namespace ratslam::fuzz {

std::vector<std::string> FuzzSeeds() {
  std::string walk =
      "#\tSiteID:5a0546857ecc773753327266\tSiteName:test\tFloorId:F2\n"
      "#\tstartTime:1574559495000\n";
  for (int i = 0; i < 100; ++i) {
    const std::string t = std::to_string(1574559495400 + 20 * i);
    walk += t + "\tTYPE_ACCELEROMETER\t0.1\t0.2\t" + std::to_string(9.8 + 3.0 * ((i / 12) % 2)) +
            "\t3\n";
    walk += t + "\tTYPE_ROTATION_VECTOR\t0.0\t0.0\t0.1\t3\n";
  }
  walk +=
      "1574559497191\tTYPE_WIFI\tFMI\ta8:0c:ca:03:9d:d7\t-49\t2422\t1574559495450\n"
      "1574559497191\tTYPE_WIFI\tIPC\t74:ee:2a:cd:eb:43\t-53\t2427\t1574559497000\n"
      "1574559495401\tTYPE_WAYPOINT\t75.371765\t94.800575\n"
      "1574559497401\tTYPE_WAYPOINT\t76.371765\t94.900575\n";
  return {walk};
}

}  // namespace ratslam::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return ratslam::fuzz::FuzzPhoneLog(
      data, size, [](const std::string& path, const ratslam::dataset::PhoneLogOptions& options) {
        return ratslam::dataset::ReadMicrosoftLog(path, options);
      });
}
