// Absolute trajectory error after a best-fit rigid alignment (rotation and translation in the
// plane, no scale), as in Sturm et al. 2012 (TUM RGB-D benchmark), solved in closed form.
#ifndef RATSLAM_FUSION_TRAJECTORY_METRICS_H_
#define RATSLAM_FUSION_TRAJECTORY_METRICS_H_

#include <optional>
#include <vector>

namespace ratslam {

struct Point2 {
  double x = 0.0;
  double y = 0.0;
};

struct RigidAlignment2D {
  double rotation_rad = 0.0;  // applied to the estimate, then the translation
  double translation_x_m = 0.0;
  double translation_y_m = 0.0;
  double rmse_m = 0.0;  // after alignment
  size_t points = 0;
};

// Best rigid transform taking `estimate` onto `truth` (same length, paired by index) in the
// least-squares sense; nullopt for fewer than 2 pairs or mismatched lengths.
std::optional<RigidAlignment2D> AlignRigid2D(const std::vector<Point2>& estimate,
                                             const std::vector<Point2>& truth);

}  // namespace ratslam

#endif  // RATSLAM_FUSION_TRAJECTORY_METRICS_H_
