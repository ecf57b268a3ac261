// Opens any supported data set by its path, and joins several into one multi-session run.
#ifndef RATSLAM_SENSORS_DATASET_DATASET_LOADER_H_
#define RATSLAM_SENSORS_DATASET_DATASET_LOADER_H_

#include <string>
#include <vector>

#include "common/status.h"
#include "sensors/dataset/dataset.h"
#include "sensors/dataset/ipin_log.h"

namespace ratslam {

enum class DatasetFormat { kReplayFolder, kIpinLog, kMicrosoftLog };

// A folder with manifest.toml: the replay format; a file whose lines look like
// `WIFI;...`/`ACCE;...` (after `%` comments): an IPIN log; tab-separated `unix_ms TYPE_...`
// lines: a Microsoft Indoor Location Competition walk. Anything else is an error naming the path.
StatusOr<DatasetFormat> DetectDatasetFormat(const std::string& path);
StatusOr<Dataset> LoadDataset(const std::string& path, const PhoneLogOptions& phone_options);

// One data set from several sessions in order: each is shifted in time to start `gap_s` after
// the previous one ends, odometry gets a zero row at each start (no motion across the gap), and
// session_start_times_s records where each begins. Image paths become absolute. Phone logs share
// the first log's geographic reference, so their ground truths share one frame.
StatusOr<Dataset> LoadSessions(const std::vector<std::string>& paths,
                               const PhoneLogOptions& phone_options, double gap_s = 1.0);

}  // namespace ratslam

#endif  // RATSLAM_SENSORS_DATASET_DATASET_LOADER_H_
