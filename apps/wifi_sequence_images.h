// The images of Wi-Fi sequence loop closure (Kudo and Miura, figs. 9 and 10), from a replay.
#ifndef RATSLAM_APPS_WIFI_SEQUENCE_IMAGES_H_
#define RATSLAM_APPS_WIFI_SEQUENCE_IMAGES_H_

#include <string>
#include <vector>

#include "common/status.h"
#include "fusion/replay_pipeline.h"
#include "render/renderer.h"
#include "viewer/figure_output.h"

namespace ratslam::apps {

// Writes wifi_sequence_similarity.png (the smoothed similarity of every pair of scans, at most
// 1000 x 1000 cells, with each loop's correspondences marked: verified, rejected) and
// wifi_sequence_pairs.png (the correspondences on the final map before and after verification)
// into `folder`, in each of `formats` (PDF and SVG on a page `width_mm` wide). `renderer` may be
// null when PNG is not among them.
Status WriteWifiSequenceImages(render::SceneRenderer* renderer,
                               const fusion::ReplayPipeline& pipeline, const std::string& folder,
                               const std::vector<viewer::FigureFormat>& formats, double width_mm);

}  // namespace ratslam::apps

#endif  // RATSLAM_APPS_WIFI_SEQUENCE_IMAGES_H_
