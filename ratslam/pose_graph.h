// Sparse least-squares optimisation of the experience graph (a 2D pose graph): the poses that
// minimise sum over links of r^T Omega r, where a link from a to b with measured translation t
// (in a's frame) and facing change phi has the residual
//   r = [ R(theta_a)^T (p_b - p_a) - t ;  wrap(theta_b - theta_a - phi) ]
// and Omega = diag(1/s_t^2, 1/s_t^2, 1/s_r^2), s_t = sigma_m + sigma_m_per_m * |t|, s_r =
// sigma_rad (the same information matrix the g2o output writes). Gauss-Newton with Eigen's sparse
// Cholesky (SimplicialLDLT); the first experience is held fixed (the gauge). Unlike RatSLAM's
// relaxation (Milford and Wyeth 2008), which spreads each link's error by a fixed share per pass,
// this converges to the globally consistent map in a few iterations, whatever the map's size.
#ifndef RATSLAM_RATSLAM_POSE_GRAPH_H_
#define RATSLAM_RATSLAM_POSE_GRAPH_H_

#include <array>
#include <vector>

#include "common/status.h"

namespace ratslam {

struct Experience;
struct Link;

struct LinkNoise {
  double sigma_m = 0.05;        // translation noise of a link, metres, plus...
  double sigma_m_per_m = 0.05;  // ...this share of the link's length
  double sigma_rad = 0.05;      // rotation noise of a link, radians

  // g2o's upper triangle of the 3x3 information matrix (I11 I12 I13 I22 I23 I33).
  std::array<double, 6> Information(double distance_m) const;
};

struct PoseGraphResult {
  int iterations = 0;
  double initial_cost = 0.0;  // sum of r^T Omega r before
  double final_cost = 0.0;    // and after
};

// Optimises the experiences' poses in place over `links` (ids index `experiences`; every link's
// ends must exist). Stops when the largest pose step falls below 1e-9 m / rad or after
// `max_iterations`. Fails, changing nothing, when the system cannot be factorised (a graph
// whose parts are not all connected to the first experience is fine: those parts are held where
// they are).
StatusOr<PoseGraphResult> OptimisePoseGraph(std::vector<Experience>* experiences,
                                            const std::vector<Link>& links, const LinkNoise& noise,
                                            int max_iterations = 20);

}  // namespace ratslam

#endif  // RATSLAM_RATSLAM_POSE_GRAPH_H_
