// Pairwise camera similarity between frames of a data set, for similarity-matrix images.
#ifndef RATSLAM_VIEWER_SIMILARITY_H_
#define RATSLAM_VIEWER_SIMILARITY_H_

#include <vector>

#include "common/status.h"
#include "dataset/dataset.h"
#include "dataset/image_loader.h"
#include "sensors/classic_camera_matcher.h"
#include "sensors/wifi_fingerprint_matcher.h"

namespace ratslam::viewer {

struct SimilarityMatrix {
  std::vector<double> times_s;  // the sampled frames
  std::vector<float> values;    // row-major, 1 = identical, 0 = as different as the 95th percentile
  double reference_difference = 0.0;  // the mean difference that maps to 0
};

// Samples at most `max_frames` evenly spaced frames, makes their templates with `options`, and
// compares every pair (best shift). Similarity = clamp(1 - d / d95, 0, 1), d95 the 95th
// percentile of all pairwise differences.
StatusOr<SimilarityMatrix> CameraSimilarityMatrix(const dataset::Dataset& dataset,
                                                  ImageLoader* images,
                                                  const sensors::ClassicCameraOptions& options,
                                                  int max_frames);

// Pairwise Wi-Fi similarity between at most `max_scans` evenly spaced scans: the weight of eq. 6
// (already in [0, 1]; 1 for identical scans).
StatusOr<SimilarityMatrix> WifiSimilarityMatrix(const dataset::Dataset& dataset,
                                                const sensors::WifiMatcherOptions& options,
                                                int max_scans);

}  // namespace ratslam::viewer

#endif  // RATSLAM_VIEWER_SIMILARITY_H_
