// The localisation benchmark's figure (the fusion paper's figures 7, 12 and 15): the rate of
// correct localisations within d and of misplaced ones beyond d, as curves over d.
#ifndef RATSLAM_VIEWER_LOCALISATION_FIGURE_H_
#define RATSLAM_VIEWER_LOCALISATION_FIGURE_H_

#include <string>
#include <vector>

#include "render/scene.h"

namespace ratslam {

struct LocalisationCurve {
  std::string label;
  std::vector<double> errors_m;  // per query: infinity for another floor, NaN for a rejection
};

// Two panels, 0..max_distance_m: correct within d (left) and misplaced beyond d (right), in %.
Scene LocalisationCurvesScene(const std::vector<LocalisationCurve>& curves,
                              const std::string& title, double max_distance_m = 30.0);

}  // namespace ratslam

#endif  // RATSLAM_VIEWER_LOCALISATION_FIGURE_H_
