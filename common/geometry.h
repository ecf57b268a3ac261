// Plane geometry shared by every layer: points, composing a pose with an offset, midpoint-rule
// dead reckoning (one definition for the experience map, the raw odometry and the outputs), and
// the best-fit rigid alignment behind absolute trajectory errors (Sturm et al. 2012, TUM RGB-D
// benchmark; rotation and translation, no scale, closed form).
#ifndef RATSLAM_COMMON_GEOMETRY_H_
#define RATSLAM_COMMON_GEOMETRY_H_

#include <cmath>
#include <optional>
#include <vector>

#include "common/circular.h"

namespace ratslam {

struct Point2 {
  double x = 0.0;
  double y = 0.0;
};

// A pose in the plane: position and heading (counter-clockwise from +x).
struct Pose2 {
  double x_m = 0.0;
  double y_m = 0.0;
  double theta_rad = 0.0;
};

// The world pose of `offset` (forward, left, facing change) taken from `base`.
inline Pose2 Compose(const Pose2& base, double forward_m, double left_m, double facing_rad) {
  return {base.x_m + forward_m * std::cos(base.theta_rad) - left_m * std::sin(base.theta_rad),
          base.y_m + forward_m * std::sin(base.theta_rad) + left_m * std::cos(base.theta_rad),
          WrapAngle(base.theta_rad + facing_rad)};
}

// Dead reckoning by the midpoint rule: move `forward_m` along the heading halfway through the
// turn, then turn by `rotation_rad`.
inline void AdvanceMidpoint(Pose2* pose, double forward_m, double rotation_rad) {
  const double heading = pose->theta_rad + 0.5 * rotation_rad;
  pose->x_m += forward_m * std::cos(heading);
  pose->y_m += forward_m * std::sin(heading);
  pose->theta_rad = WrapAngle(pose->theta_rad + rotation_rad);
}

struct RigidAlignment2D {
  double rotation_rad = 0.0;  // applied to the estimate, then the translation
  double translation_x_m = 0.0;
  double translation_y_m = 0.0;
  double rmse_m = 0.0;  // after alignment
  size_t points = 0;
};

// The alignment applied to a point of the estimate's frame, and its inverse (a truth point back
// into the estimate's frame).
inline Point2 Apply(const RigidAlignment2D& a, const Point2& p) {
  const double c = std::cos(a.rotation_rad), s = std::sin(a.rotation_rad);
  return {c * p.x - s * p.y + a.translation_x_m, s * p.x + c * p.y + a.translation_y_m};
}
inline Point2 ApplyInverse(const RigidAlignment2D& a, const Point2& p) {
  const double c = std::cos(a.rotation_rad), s = std::sin(a.rotation_rad);
  const double x = p.x - a.translation_x_m, y = p.y - a.translation_y_m;
  return {c * x + s * y, -s * x + c * y};
}

// Best rigid transform taking `estimate` onto `truth` (same length, paired by index) in the
// least-squares sense; nullopt for fewer than 2 pairs or mismatched lengths.
std::optional<RigidAlignment2D> AlignRigid2D(const std::vector<Point2>& estimate,
                                             const std::vector<Point2>& truth);

// How a saved map encodes a pose (the map file's schema: io/state_schema.h).
template <typename A>
bool Describe(A& a, Pose2& p) {
  return a(p.x_m) && a(p.y_m) && a(p.theta_rad);
}

}  // namespace ratslam

#endif  // RATSLAM_COMMON_GEOMETRY_H_
