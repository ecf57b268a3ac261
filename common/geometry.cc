#include "common/geometry.h"

#include <cmath>

namespace ratslam {

std::optional<RigidAlignment2D> AlignRigid2D(const std::vector<Point2>& estimate,
                                             const std::vector<Point2>& truth) {
  const size_t n = estimate.size();
  if (n < 2 || truth.size() != n) return std::nullopt;
  Point2 mean_e, mean_t;
  for (size_t i = 0; i < n; ++i) {
    mean_e.x += estimate[i].x;
    mean_e.y += estimate[i].y;
    mean_t.x += truth[i].x;
    mean_t.y += truth[i].y;
  }
  mean_e.x /= n;
  mean_e.y /= n;
  mean_t.x /= n;
  mean_t.y /= n;
  // The optimal angle maximises sum(t . R e) over centred points: atan2(sum cross, sum dot).
  double dot = 0.0, cross = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double ex = estimate[i].x - mean_e.x, ey = estimate[i].y - mean_e.y;
    const double tx = truth[i].x - mean_t.x, ty = truth[i].y - mean_t.y;
    dot += ex * tx + ey * ty;
    cross += ex * ty - ey * tx;
  }
  RigidAlignment2D a;
  a.rotation_rad = std::atan2(cross, dot);
  const double c = std::cos(a.rotation_rad), s = std::sin(a.rotation_rad);
  a.translation_x_m = mean_t.x - (c * mean_e.x - s * mean_e.y);
  a.translation_y_m = mean_t.y - (s * mean_e.x + c * mean_e.y);
  double sum2 = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double x = c * estimate[i].x - s * estimate[i].y + a.translation_x_m;
    const double y = s * estimate[i].x + c * estimate[i].y + a.translation_y_m;
    sum2 += (x - truth[i].x) * (x - truth[i].x) + (y - truth[i].y) * (y - truth[i].y);
  }
  a.rmse_m = std::sqrt(sum2 / n);
  a.points = n;
  return a;
}

}  // namespace ratslam
