// Loading the localisation benchmark's places from data: replay folders, IPIN or Microsoft logs
// (one, or a folder of them), UJIIndoorLoc CSVs, long-term UJI library sets and image folders with
// one sub-folder per floor. File reading lives here, beside the sessions, not in FABMAP.
#ifndef RATSLAM_SESSION_EVALUATION_NODES_H_
#define RATSLAM_SESSION_EVALUATION_NODES_H_

#include <string>
#include <vector>

#include "common/status.h"
#include "dataset/ipin_log.h"
#include "dataset/rosbag.h"
#include "dataset/video.h"
#include "fusion/fabmap/evaluation.h"

namespace ratslam::session {

// Nodes of a data set. `as_map` picks how images get scans: the temporally closest scan for the
// map, the last scan before the image for queries (the paper's section 5.2). Nodes of data
// without camera images are the Wi-Fi scans. Nodes without ground truth are skipped. Phone logs
// are read with `phone` (dead reckoning, leniency); UJIIndoorLoc with its leniency.
StatusOr<std::vector<fabmap::EvaluationNode>> LoadEvaluationNodes(
    const std::string& path, bool as_map, bool want_images,
    const fabmap::EvaluationOptions& options, const dataset::PhoneLogOptions& phone,
    const dataset::BagTopics& bag = {}, const dataset::VideoOptions& video = {});

// A query session's RSSI offset to the map (the phone's reading minus the map's, dB).
struct SessionRssiOffset {
  int session = 0;
  double offset_db = 0.0;  // 0: never known (fewer than min_estimates estimates)
};

// [evaluation] online_rssi_offset: each query session (in order of first appearance), walked in
// time order, estimates its offset to the map nodes' scans from its own scans as a phone would
// online (sensors/rssi_offset.h: the map is the reference session), and once min_estimates
// estimates exist their median is removed from its later scans. No position is used. Every
// method (FABMAP, k-NN, fingerprint) then sees the corrected scans.
std::vector<SessionRssiOffset> RemoveQueryRssiOffsets(
    const std::vector<fabmap::EvaluationNode>& map, std::vector<fabmap::EvaluationNode>* queries,
    int min_common_aps, int min_estimates);

}  // namespace ratslam::session

#endif  // RATSLAM_SESSION_EVALUATION_NODES_H_
