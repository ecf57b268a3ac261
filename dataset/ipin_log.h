// Reader for the IPIN competition smartphone logs (GetSensorData app; `;`-separated lines):
// WIFI (Wi-Fi scans, with or without the Frequency column), ACCE (accelerometer), AHRS (phone
// orientation: the compass), PRES (barometer: kept in the parsed log's streams for floor
// estimation, sensors/barometer.h), POSI (ground-truth points). Other line types are skipped.
// Odometry comes from pedestrian dead reckoning over ACCE and AHRS, run after parsing
// (phone_log.h). Ground truth: latitude and longitude to local metres (x east, y north) about a
// reference point, the floor kept; the replay interpolates linearly between points (the walkers
// moved in straight lines at constant speed between them). All times are the app timestamps (one
// clock for every sensor).
#ifndef RATSLAM_DATASET_IPIN_LOG_H_
#define RATSLAM_DATASET_IPIN_LOG_H_

#include <optional>
#include <string>

#include "common/status.h"
#include "dataset/dataset.h"
#include "dataset/phone_log.h"

namespace ratslam::dataset {

// Local east/north metres of a latitude/longitude about `reference` (equirectangular; exact to
// millimetres over a building).
void GeoToLocal(const GeoReference& reference, double latitude_deg, double longitude_deg,
                double* x_m, double* y_m);

// Parses one log into its raw streams (no dead reckoning). Errors name the file and line
// ("log.txt:812: WIFI: RSS(dBm) is not a number").
StatusOr<PhoneLog> ParseIpinLog(const std::string& path, const PhoneLogOptions& options,
                                PhoneLogReport* report = nullptr);
// ParseIpinLog, then PhoneLogToDataset (phone_log.h): the log as a replay data set.
StatusOr<Dataset> ReadIpinLog(const std::string& path, const PhoneLogOptions& options,
                              PhoneLogReport* report = nullptr);

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_IPIN_LOG_H_
