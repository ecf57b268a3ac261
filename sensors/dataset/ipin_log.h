// Reader for the IPIN competition smartphone logs (GetSensorData app; `;`-separated lines):
// WIFI (Wi-Fi scans, with or without the Frequency column), ACCE (accelerometer), AHRS (phone
// orientation: the compass), POSI (ground-truth points). Other line types are skipped.
// Odometry comes from pedestrian dead reckoning over ACCE and AHRS. Ground truth: latitude and
// longitude to local metres (x east, y north) about a reference point, the floor kept; the
// replay interpolates linearly between points (the walkers moved in straight lines at constant
// speed between them). All times are the app timestamps (one clock for every sensor).
#ifndef RATSLAM_SENSORS_DATASET_IPIN_LOG_H_
#define RATSLAM_SENSORS_DATASET_IPIN_LOG_H_

#include <fstream>
#include <map>
#include <optional>
#include <string>

#include "common/status.h"
#include "sensors/dataset/dataset.h"
#include "sensors/pedestrian_dead_reckoning.h"

namespace ratslam {

struct GeoReference {
  double latitude_deg = 0.0;
  double longitude_deg = 0.0;
};

// Local east/north metres of a latitude/longitude about `reference` (equirectangular; exact to
// millimetres over a building).
void GeoToLocal(const GeoReference& reference, double latitude_deg, double longitude_deg,
                double* x_m, double* y_m);

struct PhoneLogOptions {
  bool lenient = false;           // skip (and count) malformed lines instead of failing
  PdrOptions pdr;                 // step detection and length
  double compass_rate_hz = 10.0;  // compass events kept per second (AHRS arrives at ~100 Hz)
  std::optional<GeoReference> reference;  // default: the log's first POSI point
};

struct PhoneLogReport {
  size_t lines = 0;
  size_t skipped_malformed = 0;  // only in lenient mode
  size_t skipped_other_types = 0;
  size_t steps = 0;
  GeoReference reference;  // the reference actually used
};

// Reads one log. Errors name the file and line ("log.txt:812: WIFI: RSS(dBm) is not a number").
StatusOr<Dataset> ReadIpinLog(const std::string& path, const PhoneLogOptions& options,
                              PhoneLogReport* report = nullptr);

// Checks the options and opens a phone log (a regular file) for reading (shared by the phone log
// readers).
Status OpenPhoneLog(const std::string& path, const PhoneLogOptions& options, std::ifstream* in);
// Reads line `number + 1` of a phone log into *line (at most kMaxLineBytes; longer is an error
// naming the line); *more is false at the end of the file.
Status ReadPhoneLogLine(std::istream& in, const std::string& path, int number, std::string* line,
                        bool* more);

// What a phone log reader collects, before it becomes a data set.
struct PhoneLogStreams {
  std::vector<AccelerometerSample> accelerometer;
  std::vector<HeadingSample> headings;
  std::map<double, std::vector<WifiReading>> scans;  // readings by scan time
  std::vector<GroundTruthRow> ground_truth;
};

// Sorts the streams, runs dead reckoning, thins the compass to compass_rate_hz, and gives each
// ground-truth point the heading towards the next. Shared by the phone log readers.
Dataset AssemblePhoneDataset(PhoneLogStreams streams, const std::string& name,
                             const PhoneLogOptions& options, double start_time_s,
                             PhoneLogReport* report);

// Builds odometry rows from pedestrian dead-reckoning steps: a zero row at `start_time_s`, then
// one row per step carrying its length and heading change over the time since the previous row.
std::vector<OdometryRow> StepsToOdometry(const std::vector<Step>& steps, double start_time_s);

}  // namespace ratslam

#endif  // RATSLAM_SENSORS_DATASET_IPIN_LOG_H_
