// The invariant every data-set reader must keep: what it returns can be written in the replay
// format and read back, with the same rows. `ratslam import` depends on it.
#ifndef RATSLAM_FUZZ_DATASET_ROUND_TRIP_H_
#define RATSLAM_FUZZ_DATASET_ROUND_TRIP_H_

#include <cmath>
#include <filesystem>
#include <string>

#include "dataset/dataset.h"
#include "dataset/ipin_log.h"
#include "fuzz/fuzz_support.h"

namespace ratslam::fuzz {

inline size_t Readings(const dataset::Dataset& d) {
  size_t n = 0;
  for (const WifiScan& s : d.wifi) n += s.readings.size();
  return n;
}

inline void CheckWritesAndReadsBack(const dataset::Dataset& d) {
  const std::string folder = (Scratch() / "round_trip").string();
  std::filesystem::remove_all(folder);  // nothing left from the previous input
  const Status written = dataset::WriteDataset(d, folder);
  if (!written.ok()) {
    // Refusing to write a value the reader cannot give back is allowed, and must say so.
    if (written.message().find("cannot be stored") == std::string::npos &&
        written.message().find("not writable") == std::string::npos) {
      InvariantFailed("write failed: " + written.message());
    }
    return;
  }
  StatusOr<dataset::Dataset> back = dataset::ReadDataset(folder);
  if (!back.ok())
    InvariantFailed("a written data set does not read back: " + back.status().message());
  if (back->odometry.size() != d.odometry.size() || back->images.size() != d.images.size() ||
      back->ground_truth.size() != d.ground_truth.size() ||
      back->compass.size() != d.compass.size() || back->pressure.size() != d.pressure.size() ||
      Readings(*back) != Readings(d)) {
    InvariantFailed("a written data set reads back with other row counts");
  }
}

// One phone-log input through `read` (strict, then lenient): an error names the file, and an
// accepted log becomes a data set that writes and reads back.
template <typename Reader>
int FuzzPhoneLog(const uint8_t* data, size_t size, Reader read) {
  const std::string path = WriteScratchFile("log.txt", data, size);
  for (bool lenient : {false, true}) {
    dataset::PhoneLogOptions options;
    options.lenient = lenient;
    StatusOr<dataset::Dataset> d = read(path, options);
    if (!d.ok()) {
      if (d.status().message().rfind(path, 0) != 0) {
        InvariantFailed("error does not name the file: " + d.status().message());
      }
      continue;
    }
    CheckWritesAndReadsBack(*d);
  }
  return 0;
}

}  // namespace ratslam::fuzz

#endif  // RATSLAM_FUZZ_DATASET_ROUND_TRIP_H_
