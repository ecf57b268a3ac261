// Opens any supported data set by its path, and joins several into one multi-session run.
#ifndef RATSLAM_DATASET_DATASET_LOADER_H_
#define RATSLAM_DATASET_DATASET_LOADER_H_

#include <functional>
#include <string>
#include <vector>

#include "common/status.h"
#include "dataset/dataset.h"
#include "dataset/ipin_log.h"
#include "dataset/rosbag.h"
#include "dataset/video.h"

namespace ratslam::dataset {

enum class DatasetFormat { kReplayFolder, kIpinLog, kMicrosoftLog, kRosBag, kRos2Bag, kVideo };

// A folder with manifest.toml: the replay format; a file starting "#ROSBAG V2.0": a ROS 1 bag
// (topics from `bag`); an MCAP file, a rosbag2 sqlite3 file or a folder with metadata.yaml: a ROS 2
// bag (dataset/rosbag2.h, topics from `bag`); a file named like a video (.avi, .mp4, ...):
// a video with its odometry log (dataset/video.h); a file whose lines look like
// `WIFI;...`/`ACCE;...` (after `%` comments): an IPIN log; tab-separated `unix_ms TYPE_...`
// lines: a Microsoft Indoor Location Competition walk. Anything else is an error naming the path.
StatusOr<DatasetFormat> DetectDatasetFormat(const std::string& path);
StatusOr<Dataset> LoadDataset(const std::string& path, const PhoneLogOptions& phone_options,
                              const BagTopics& bag = {}, const VideoOptions& video = {});

// One data set from several sessions in order: each is shifted in time to start `gap_s` after
// the previous one ends, odometry gets a zero row at each start (no motion across the gap), and
// session_start_times_s records where each begins. Image paths become absolute. Phone logs share
// the first log's geographic reference, so their ground truths share one frame.
StatusOr<Dataset> LoadSessions(const std::vector<std::string>& paths,
                               const PhoneLogOptions& phone_options, double gap_s = 1.0,
                               const BagTopics& bag = {}, const VideoOptions& video = {});

// Copies every image of `dataset` (files, or messages of a ROS bag, stored as the bag holds them:
// JPEG stays JPEG) into `folder`/images as 000000.<ext>, 000001.<ext>, ... and points the rows
// at the copies, so that WriteDataset(dataset, folder) then makes a self-contained data set.
// `progress` (may be empty) is called with (done, total) every 500 images. A failure names the
// image; the manifest is not written by this call, so a half-copied folder never reads as a
// data set.
Status CopyImagesInto(Dataset* dataset, const std::string& folder,
                      const std::function<void(size_t, size_t)>& progress = {});

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_DATASET_LOADER_H_
