// The images of a replay: experience map, template graph and pose-cell activity, drawn from a
// run's records (at the end of a run, or from a resumed map); the viewer never sees the pipeline.
#ifndef RATSLAM_VIEWER_RUN_IMAGES_H_
#define RATSLAM_VIEWER_RUN_IMAGES_H_

#include <string>

#include "common/status.h"
#include "dataset/dataset.h"
#include "ratslam/records.h"
#include "render/renderer.h"
#include "viewer/figure_output.h"
#include "viewer/figures.h"

namespace ratslam::viewer {

// The ground truth up to `until_time_s`, moved into the map's frame by the rigid fit of the
// experiences to the ground truth at their creation times; empty without ground truth.
// `floors`, if given, receives the floor of each returned point.
std::vector<Point2> GroundTruthInMapFrame(const std::vector<Experience>& experiences,
                                          const dataset::Dataset& dataset, double until_time_s,
                                          std::vector<int>* floors = nullptr);

// The floor of each experience: the ground truth's floor at its creation; where there is none
// (before a walk's first point, between two walks), the floor of the point nearest in time; 0
// without ground truth.
std::vector<int> ExperienceFloors(const std::vector<Experience>& experiences,
                                  const dataset::Dataset& dataset);

// How ExperienceMapFloorsScene laid out its panels (columns 0: a single map, no panels).
struct FloorPanels {
  int columns = 0;
  int panel_width_px = 0, panel_height_px = 0;
  int top_px = 0;           // the first row's top; panel k is at column k % columns
  std::vector<int> floors;  // ascending, one per panel
};

// One experience-map panel per floor, all at one scale, each showing that floor's experiences,
// the links between them and that floor's ground truth, in a grid within `figure`'s size under
// one title, with one legend and scale bar (in the last panel). `columns` 0 picks the grid that
// draws the map largest. A single floor gives the ordinary map.
render::Scene ExperienceMapFloorsScene(const ExperienceMapImageData& data,
                                       const std::vector<int>& experience_floors,
                                       const std::vector<int>& ground_truth_floors,
                                       const ExperienceMapImageOptions& figure, int columns = 0,
                                       FloorPanels* layout = nullptr);

// The experience-map figure data of a run, with the ground truth (if any) aligned to the map.
ExperienceMapImageData ExperienceMapDataOf(const RunView& run, const dataset::Dataset& dataset);
// What `replay --render` draws as experience_map: coloured by session for a multi-session data
// set, the ground truth the run reached by `until_time_s` aligned to the map, one panel per floor
// (ExperienceMapFloorsScene); `render experience-map` draws the same from a run folder.
struct ExperienceMapFigure {
  ExperienceMapImageData data;
  std::vector<int> floors;        // per experience
  std::vector<int> truth_floors;  // per ground-truth point of data.ground_truth
  ExperienceMapImageOptions options;
};
ExperienceMapFigure ExperienceMapFigureOf(ExperienceMapImageData data,
                                          const dataset::Dataset& dataset, double until_time_s);

// One template-graph point per view frame.
std::vector<TemplateGraphPoint> TemplateGraphOf(const RunView& run);

// Writes experience_map, template_graph and pose_cells into `folder` in each of `formats` (PNG
// through `renderer`, which may be null without PNG; PDF and SVG on pages `width_mm` wide).
Status WriteRunImages(render::SceneRenderer* renderer, const RunView& run,
                      const dataset::Dataset& dataset, const std::string& folder,
                      const std::vector<FigureFormat>& formats = {FigureFormat::kPng},
                      double width_mm = render::kOneColumnMm);

}  // namespace ratslam::viewer

#endif  // RATSLAM_VIEWER_RUN_IMAGES_H_
