// Reader for UJIIndoorLoc fingerprint files (Torres-Sospedra et al., IPIN 2014): a CSV with
// columns WAP001..WAPnnn (RSSI in dBm; 100 means not detected), LONGITUDE and LATITUDE (projected
// metres), FLOOR, BUILDINGID, SPACEID, RELATIVEPOSITION, USERID, PHONEID, TIMESTAMP. Reference
// fingerprints, not a trajectory: each row is a labelled scan.
#ifndef RATSLAM_DATASET_UJIINDOORLOC_H_
#define RATSLAM_DATASET_UJIINDOORLOC_H_

#include <string>
#include <vector>

#include "common/status.h"
#include "dataset/dataset.h"

namespace ratslam::dataset {

struct LabelledScan {
  std::vector<WifiReading> readings;  // detected APs only (bssid = the column name)
  double x_m = 0.0, y_m = 0.0;
  int floor = 0;
  int building = 0;
  int space = 0;
  int user = 0;
  int phone = 0;
  double time_s = 0.0;
  int line = 0;  // in the file, for messages
};

struct UjiReadReport {
  size_t rows = 0;
  size_t skipped_malformed = 0;  // lenient mode only
  size_t access_points = 0;
};

// Errors name the file, line and column; `lenient` skips and counts malformed rows.
StatusOr<std::vector<LabelledScan>> ReadUjiIndoorLoc(const std::string& path, bool lenient = false,
                                                     UjiReadReport* report = nullptr);

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_UJIINDOORLOC_H_
