// Loading the localisation benchmark's places from data: replay folders, IPIN or Microsoft logs
// (one, or a folder of them), UJIIndoorLoc CSVs, long-term UJI library sets and image folders with
// one sub-folder per floor. File reading lives here, beside the sessions, not in FABMAP.
#ifndef RATSLAM_SESSION_EVALUATION_NODES_H_
#define RATSLAM_SESSION_EVALUATION_NODES_H_

#include <string>
#include <vector>

#include "common/status.h"
#include "fusion/fabmap/evaluation.h"
#include "sensors/dataset/ipin_log.h"
#include "sensors/dataset/rosbag.h"
#include "sensors/dataset/video.h"

namespace ratslam {

// Nodes of a data set. `as_map` picks how images get scans: the temporally closest scan for the
// map, the last scan before the image for queries (the paper's section 5.2). Nodes of data
// without camera images are the Wi-Fi scans. Nodes without ground truth are skipped. Phone logs
// are read with `phone` (dead reckoning, leniency); UJIIndoorLoc with its leniency.
StatusOr<std::vector<fabmap::EvaluationNode>> LoadEvaluationNodes(
    const std::string& path, bool as_map, bool want_images,
    const fabmap::EvaluationOptions& options, const PhoneLogOptions& phone,
    const BagTopics& bag = {}, const VideoOptions& video = {});

}  // namespace ratslam

#endif  // RATSLAM_SESSION_EVALUATION_NODES_H_
