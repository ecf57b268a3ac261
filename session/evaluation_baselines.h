// Simple Wi-Fi localisers that `ratslam evaluate` runs beside FABMAP on the same map and queries,
// so every table compares against a baseline measured in the same run.
//
// knn: weighted k-nearest fingerprints (the usual Wi-Fi fingerprinting baseline, e.g. the
//   UJIIndoorLoc paper's). Representation: a vector of RSSI in dBm over every access point of
//   the map and the query, an AP a scan did not hear at kKnnNotHeardDbm (below any reading the
//   data sets hold; repeated readings of one BSSID in a scan are averaged). Distance: Euclidean
//   over those vectors (only APs heard by either scan contribute). The k = kKnnNeighbours nearest
//   map scans (ties: the lower map index) vote for a floor with weights 1 / max(d, 1e-3 dB); the
//   estimate is the weighted mean position of the neighbours on the winning floor (ties between
//   floors: the floor of the nearest neighbour). It never rejects a query that has a scan.
// fingerprint: our eq. 6 matcher (sensors/wifi_fingerprint_matcher.h, `[wifi]` options) as a
//   localiser: the map scan with the largest weight, a rejection when no map scan reaches
//   `match_threshold` (t_wifi) or shares an AP.
// Queries without a scan, and map nodes without one, take no part (such a query is rejected).
#ifndef RATSLAM_SESSION_EVALUATION_BASELINES_H_
#define RATSLAM_SESSION_EVALUATION_BASELINES_H_

#include <vector>

#include "fusion/fabmap/evaluation.h"
#include "sensors/wifi_fingerprint_matcher.h"

namespace ratslam::session {

inline constexpr int kKnnNeighbours = 3;
inline constexpr double kKnnNotHeardDbm = -110.0;

std::vector<fabmap::Estimate> KnnEstimates(const std::vector<fabmap::EvaluationNode>& map,
                                           const std::vector<fabmap::EvaluationNode>& queries,
                                           int k = kKnnNeighbours);

// `options` must be valid (throws std::invalid_argument otherwise, as the matcher does).
std::vector<fabmap::Estimate> FingerprintEstimates(
    const std::vector<fabmap::EvaluationNode>& map,
    const std::vector<fabmap::EvaluationNode>& queries, const sensors::WifiMatcherOptions& options);

}  // namespace ratslam::session

#endif  // RATSLAM_SESSION_EVALUATION_BASELINES_H_
