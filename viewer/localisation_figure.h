// The localisation benchmark's figure (the fusion paper's figures 7, 12 and 15): the rate of
// correct localisations within d and of misplaced ones beyond d, as curves over d.
#ifndef RATSLAM_VIEWER_LOCALISATION_FIGURE_H_
#define RATSLAM_VIEWER_LOCALISATION_FIGURE_H_

#include <string>
#include <vector>

#include "render/scene.h"

namespace ratslam::viewer {

struct LocalisationCurve {
  std::string label;
  std::vector<double> errors_m;  // per query: infinity for another floor, NaN for a rejection
};

// Where the curves' distance axis should end: the largest finite error of any curve, rounded up
// to a multiple of 5 m (at least 5), and at most `at_most_m` (an axis running far past the data
// squeezed the curves into its first third).
double LocalisationAxisEndM(const std::vector<LocalisationCurve>& curves, double at_most_m = 30.0);

// Two panels, 0..max_distance_m: correct within d (left) and misplaced beyond d (right), in %.
// `width_px` > 0 lays the figure out that wide (for vector output); 0: the natural 1380 px.
render::Scene LocalisationCurvesScene(const std::vector<LocalisationCurve>& curves,
                                      const std::string& title, double max_distance_m = 30.0,
                                      int width_px = 0);

// Precision (y) against recall (x), both 0..100 %, one curve per distance d of `labels`:
// `recall[k]` and `precision[k]` are the points of curve k, from the highest threshold down.
// `width_px` as for LocalisationCurvesScene (natural: 710 px).
render::Scene PrecisionRecallScene(
    const std::vector<std::string>& labels, const std::vector<std::vector<double>>& recall,
    const std::vector<std::vector<double>>& precision, const std::string& title, int width_px = 0,
    const std::string& subtitle = "accepted: the best place's posterior >= a threshold");

// Image-sequence place recognition: the difference matrix (queries down, references across;
// darker is more alike, each query row stretched over its own range, blank references white), the
// true places as a thin line and each query's answer as a dot, green within the tolerance and red
// beyond. Large matrices are averaged down to at most `max_cells` a side.
struct DifferenceMatrixFigure {
  std::vector<std::vector<float>> differences;  // [query][reference]
  std::vector<int> answers;                     // per query; -1 declined
  std::vector<int> truth;                       // per query; -1 unknown
  std::vector<bool> blank_references;           // drawn white: never an answer
  int frame_tolerance = 1;
  std::string title;
  int max_cells = 600;
};
render::Scene DifferenceMatrixScene(const DifferenceMatrixFigure& figure);

}  // namespace ratslam::viewer

#endif  // RATSLAM_VIEWER_LOCALISATION_FIGURE_H_
