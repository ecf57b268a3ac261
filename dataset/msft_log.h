// Reader for the Microsoft Indoor Location Competition 2.0 walks (`path_data_files/*.txt`):
// `#` header lines, then tab-separated `unix_ms TYPE values...`. Used: TYPE_WIFI (ssid, bssid,
// rssi, frequency, last_seen_ms; readings with one timestamp form one scan; readings last seen
// more than max_wifi_staleness_s before the scan are Android's cached results and are dropped),
// TYPE_ACCELEROMETER (for dead reckoning, run after parsing), TYPE_ROTATION_VECTOR (the phone's
// heading: where its y axis points in the East-North-Up frame), TYPE_WAYPOINT (ground truth in
// metres). The floor comes from the header's FloorName (B1 = -1, F1 = 0, F2 = 1, ...). Times are
// seconds since the header's startTime (or the first line). Other types are skipped.
#ifndef RATSLAM_DATASET_MSFT_LOG_H_
#define RATSLAM_DATASET_MSFT_LOG_H_

#include <string>

#include "common/status.h"
#include "dataset/dataset.h"
#include "dataset/phone_log.h"

namespace ratslam::dataset {

// Floor number of a FloorName such as "B2", "F1", "F3"; nullopt for anything else.
std::optional<int> FloorFromName(const std::string& name);

// Heading (counter-clockwise from east) of the device's y axis for an Android rotation vector
// (x, y, z: the vector part of the unit quaternion from device to East-North-Up).
double HeadingFromRotationVector(double x, double y, double z);

// Parses one walk into its raw streams (no dead reckoning); errors name the file and line.
StatusOr<PhoneLog> ParseMicrosoftLog(const std::string& path, const PhoneLogOptions& options,
                                     PhoneLogReport* report = nullptr,
                                     double max_wifi_staleness_s = 10.0);
// ParseMicrosoftLog, then PhoneLogToDataset (phone_log.h): the walk as a replay data set.
StatusOr<Dataset> ReadMicrosoftLog(const std::string& path, const PhoneLogOptions& options,
                                   PhoneLogReport* report = nullptr,
                                   double max_wifi_staleness_s = 10.0);

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_MSFT_LOG_H_
