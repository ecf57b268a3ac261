// A sweep's figures, from its collected points: the objective against each parameter, a heat
// map over two parameters (the best objective over the others in each cell), and the Pareto
// front of objective against run time. Plain data in, scenes out. `width_px` 0 lays a figure
// out at its natural width; another value fits it to that width (vector figures, whose page
// width sets the text size: viewer/figure_output.h).
#ifndef RATSLAM_VIEWER_SWEEP_FIGURES_H_
#define RATSLAM_VIEWER_SWEEP_FIGURES_H_

#include <optional>
#include <string>
#include <vector>

#include "render/scene.h"

namespace ratslam::viewer {

struct SweepFigurePoint {
  std::vector<std::string> values;  // one per parameter key, as written in the plan
  std::optional<double> objective;  // none when a run of the point failed or never ran
  double mean_wall_s = 0.0;         // per run
};

struct SweepFigureData {
  std::string title;      // e.g. the sweep file
  std::string objective;  // the metric's name
  bool minimize = true;
  std::vector<std::string> keys;
  std::vector<SweepFigurePoint> points;
  std::optional<int> best;  // index into points
};

// One panel per parameter: every ranked point's objective over that parameter's values
// (numbers on a linear axis, other values in plan order), the best point in red.
render::Scene SweepParameterScene(const SweepFigureData& data, int width_px = 0);
// Cells over the values of keys[a] (x) and keys[b] (y), coloured and labelled with the best
// objective among the points that share them.
render::Scene SweepHeatmapScene(const SweepFigureData& data, int a, int b, int width_px = 0);
// Objective against mean run time; the points no other point beats in both are the front.
render::Scene SweepParetoScene(const SweepFigureData& data, int width_px = 0);

}  // namespace ratslam::viewer

#endif  // RATSLAM_VIEWER_SWEEP_FIGURES_H_
