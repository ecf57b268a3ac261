// Reads a replay's output folder back (experiences.csv, links.csv, frames.csv) for rendering.
#ifndef RATSLAM_IO_RUN_READER_H_
#define RATSLAM_IO_RUN_READER_H_

#include <optional>
#include <string>
#include <vector>

#include "common/sensor_samples.h"
#include "common/status.h"
#include "ratslam/experience_map.h"
#include "ratslam/records.h"

namespace ratslam::io {

struct RunFolder {
  std::vector<Experience> experiences;
  std::vector<Link> links;
  std::vector<FrameRecord> frames;
  std::string dataset_folder;                  // from summary.json, if recorded
  std::vector<std::string> inputs;             // the data sets the run read (summary.json's run)
  std::string dataset_name;                    // from summary.json, if recorded
  std::optional<uint32_t> current_experience;  // from summary.json, if recorded
};

// Errors name the file, line and column; ids must be consecutive and links must refer to
// existing experiences.
StatusOr<RunFolder> ReadRunFolder(const std::string& folder);

// A TUM trajectory file (`timestamp tx ty tz qx qy qz qw` per line, `#` comments), e.g. a run's
// trajectory_tum.txt, as planar poses: x, y and the yaw of the quaternion (floor 0). Errors name
// the file, line and field: a missing or non-finite field, or a time not after the previous one.
StatusOr<std::vector<GroundTruthRow>> ReadTumTrajectory(const std::string& path);

}  // namespace ratslam::io

#endif  // RATSLAM_IO_RUN_READER_H_
