// Phone logs (IPIN, Microsoft) in two steps: a reader parses a log into its raw streams
// (`PhoneLog`; ipin_log.h, msft_log.h), and `PhoneLogToDataset` turns those into a replay data
// set by pedestrian dead reckoning. Parsing never runs dead reckoning, so a caller can inspect,
// fix or re-reckon the raw streams (other PDR settings, gesture detection) without re-reading.
#ifndef RATSLAM_DATASET_PHONE_LOG_H_
#define RATSLAM_DATASET_PHONE_LOG_H_

#include <istream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/sensor_samples.h"
#include "common/status.h"
#include "dataset/dataset.h"
#include "sensors/pedestrian_dead_reckoning.h"

namespace ratslam::dataset {

// The point local metres are measured from (IPIN logs carry latitude and longitude).
struct GeoReference {
  double latitude_deg = 0.0;
  double longitude_deg = 0.0;
};

struct PhoneLogOptions {
  bool lenient = false;           // parsing: skip (and count) malformed lines instead of failing
  sensors::PdrOptions pdr;        // dead reckoning: step detection and length
  double compass_rate_hz = 10.0;  // compass events kept per second (AHRS arrives at ~100 Hz)
  std::optional<GeoReference> reference;  // parsing: default is the log's first POSI point
};

struct PhoneLogReport {
  size_t lines = 0;
  size_t skipped_malformed = 0;  // only in lenient mode
  size_t skipped_other_types = 0;
  size_t steps = 0;              // set by PhoneLogToDataset
  size_t steps_not_walking = 0;  // dropped by the orientation test (gestures), ditto
  GeoReference reference;        // the reference actually used
};

// What a phone log reader collects, in file order.
struct PhoneLogStreams {
  std::vector<sensors::AccelerometerSample> accelerometer;
  std::vector<sensors::HeadingSample> headings;
  std::map<double, std::vector<WifiReading>> scans;  // readings by scan time
  std::vector<GroundTruthRow> ground_truth;          // headings not yet set
  std::vector<PressureSample> pressure;              // barometer (IPIN's PRES), hPa
};

struct PhoneLog {
  std::string name;           // the file's stem
  double start_time_s = 0.0;  // time of the first line: odometry starts here
  PhoneLogStreams streams;
};

// Opens a phone log (a regular file) for reading.
Status OpenPhoneLog(const std::string& path, std::ifstream* in);
// Reads line `number + 1` of a phone log into *line (at most kMaxLineBytes; longer is an error
// naming the line); *more is false at the end of the file.
Status ReadPhoneLogLine(std::istream& in, const std::string& path, int number, std::string* line,
                        bool* more);

// Sorts the streams by time, runs dead reckoning (options.pdr) into odometry, thins the compass
// to options.compass_rate_hz, and gives each ground-truth point the heading towards the next.
// Fails only on invalid options.
StatusOr<Dataset> PhoneLogToDataset(PhoneLog log, const PhoneLogOptions& options,
                                    PhoneLogReport* report = nullptr);

// Builds odometry rows from pedestrian dead-reckoning steps: a zero row at `start_time_s`, then
// one row per step carrying its length and heading change over the time since the previous row.
std::vector<OdometryRow> StepsToOdometry(const std::vector<sensors::Step>& steps,
                                         double start_time_s);

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_PHONE_LOG_H_
