// Reads a replay's output folder back (experiences.csv, links.csv, frames.csv) for rendering.
#ifndef RATSLAM_FUSION_IO_RUN_READER_H_
#define RATSLAM_FUSION_IO_RUN_READER_H_

#include <string>
#include <vector>

#include "common/status.h"
#include "ratslam/experience_map.h"
#include "ratslam/records.h"

namespace ratslam {

struct RunFolder {
  std::vector<Experience> experiences;
  std::vector<Link> links;
  std::vector<FrameRecord> frames;
  std::string dataset_folder;  // from summary.json, if recorded
};

// Errors name the file, line and column; ids must be consecutive and links must refer to
// existing experiences.
StatusOr<RunFolder> ReadRunFolder(const std::string& folder);

}  // namespace ratslam

#endif  // RATSLAM_FUSION_IO_RUN_READER_H_
