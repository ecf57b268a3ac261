// The ground-truth map of a simulated world: walls (by material), access points, disturbances
// and the true trajectory, one panel per floor.
#ifndef RATSLAM_VIEWER_WORLD_FIGURE_H_
#define RATSLAM_VIEWER_WORLD_FIGURE_H_

#include "dataset/dataset.h"
#include "render/scene.h"
#include "sim/world.h"

namespace ratslam::viewer {

render::Scene WorldMapScene(const sim::World& world, const dataset::Dataset& dataset,
                            int panel_px = 700);

}  // namespace ratslam::viewer

#endif  // RATSLAM_VIEWER_WORLD_FIGURE_H_
