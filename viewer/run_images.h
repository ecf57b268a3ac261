// The images of a replay: experience map, template graph and pose-cell activity, drawn from the
// pipeline's state (at the end of a run, or from a resumed map).
#ifndef RATSLAM_VIEWER_RUN_IMAGES_H_
#define RATSLAM_VIEWER_RUN_IMAGES_H_

#include <string>

#include "fusion/replay_pipeline.h"
#include "ratslam/status.h"
#include "viewer/figures.h"
#include "viewer/renderer.h"

namespace ratslam {

// The ground truth up to `until_time_s`, moved into the map's frame by the rigid fit of the
// experiences to the ground truth at their creation times; empty without ground truth.
std::vector<Point2> GroundTruthInMapFrame(const std::vector<Experience>& experiences,
                                          const Dataset& dataset, double until_time_s);

// The experience-map figure data of a run, with the ground truth (if any) aligned to the map.
ExperienceMapImageData ExperienceMapDataOf(const ReplayPipeline& pipeline, const Dataset& dataset);
// One template-graph point per view frame.
std::vector<TemplateGraphPoint> TemplateGraphOf(const ReplayPipeline& pipeline);

// Writes experience_map.png, template_graph.png and pose_cells.png into `folder`.
Status WriteRunImages(SceneRenderer& renderer, const ReplayPipeline& pipeline,
                      const Dataset& dataset, const std::string& folder);

}  // namespace ratslam

#endif  // RATSLAM_VIEWER_RUN_IMAGES_H_
