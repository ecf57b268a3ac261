// The replay data-set format: a folder with `manifest.toml` and one CSV per stream, plus an
// image folder. Times are in seconds; units are in the column names. See
// docs/data-formats.md for the full description.
#ifndef RATSLAM_DATASET_DATASET_H_
#define RATSLAM_DATASET_DATASET_H_

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/sensor_samples.h"
#include "common/status.h"

namespace ratslam::dataset {

struct Dataset {
  std::string name;
  std::string folder;                   // where it was read from (empty for one made in memory)
  std::string image_folder = "images";  // relative to `folder`
  std::vector<OdometryRow> odometry;
  std::vector<ImageRow> images;
  std::vector<GroundTruthRow> ground_truth;
  std::vector<WifiScan> wifi;
  std::vector<CompassRow> compass;
  std::vector<PressureSample> pressure;       // barometer, hPa (floors: sensors/barometer.h)
  std::vector<double> session_start_times_s;  // more than one for a multi-session run
  // One per session start when known (empty otherwise): what figures and summaries call them.
  std::vector<std::string> session_names;
  // Lines of phone logs that were malformed and skipped (only with lenient reading).
  size_t skipped_malformed_lines = 0;

  // The image's path: `file` itself when absolute, else inside the image folder.
  std::string ImagePath(const ImageRow& row) const;
  // The name of session `index`: its recorded name, else "session N" (1-based).
  std::string SessionName(size_t index) const;
  // The session a time belongs to: the last one started at or before it (0 before any).
  size_t SessionAt(double time_s) const;
};

// Reads a replay data-set folder. Errors name the file, line and column. Streams must be regular
// files inside the folder; times must be non-negative and never go backwards.
StatusOr<Dataset> ReadDataset(const std::string& folder);

// Writes `dataset` (without images) into `folder` (created if needed): manifest and CSVs with
// every number printed so that it reads back bit for bit. What the reader would refuse (a BSSID
// or file name with a comma, a non-finite number) is an error before anything is written; each
// file is written atomically and checked, and the manifest last, so a failed write never leaves
// a data set that reads as complete.
Status WriteDataset(const Dataset& dataset, const std::string& folder);

// Events in replay order.
enum class EventType : uint8_t {
  kCompass = 0,
  kWifi = 1,
  kImage = 2,
  kOdometry = 3,
  kPressure = 4
};
struct Event {
  double time_s = 0.0;
  EventType type = EventType::kOdometry;
  uint32_t index = 0;  // into the stream's vector
};
// All events sorted by time; at equal times compass, pressure, Wi-Fi, images, then odometry (so
// that an odometry step's action sees the view of the same instant), then by index.
std::vector<Event> MergeEvents(const Dataset& dataset);

// Ground-truth position at `time_s`, linearly interpolated; nullopt outside the covered span.
// With `session_starts` (a data set's `session_start_times_s`), nothing is interpolated between
// two rows of different sessions (see GroundTruthAt).
std::optional<GroundTruthRow> InterpolateGroundTruth(
    const std::vector<GroundTruthRow>& rows, double time_s,
    const std::vector<double>& session_starts = {});

// The floor at `time_s` when the ground-truth points either side of it agree (or one falls on it);
// nullopt between two points on different floors (the walker changed floor somewhere between,
// on the stairs) and outside the covered span.
std::optional<int> KnownFloor(const std::vector<GroundTruthRow>& rows, double time_s,
                              const std::vector<double>& session_starts = {});

// These two for a data set that may join several sessions (walks recorded apart, laid on one
// clock by `session_start_times_s`): nothing is interpolated between two rows of different
// sessions, so the time from one session's last ground-truth point to the next one's first (the
// end of one recording and the start of the next, e.g. a phone's calibration minute) has no
// ground truth, as the time before the first session's first point has none. What is scored
// (match distances, ATE, floors) is then what was measured.
std::optional<GroundTruthRow> GroundTruthAt(const Dataset& dataset, double time_s);
std::optional<int> KnownFloorAt(const Dataset& dataset, double time_s);

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_DATASET_H_
