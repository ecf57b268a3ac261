#include "ratslam/pose_graph.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <cmath>
#include <numeric>

#include "common/circular.h"
#include "ratslam/experience_map.h"

namespace ratslam {

std::array<double, 6> LinkNoise::Information(double distance_m) const {
  const double st = sigma_m + sigma_m_per_m * distance_m;
  const double t = 1.0 / (st * st);
  const double r = 1.0 / (sigma_rad * sigma_rad);
  return {t, 0.0, 0.0, t, 0.0, r};
}

namespace {

struct Residual {
  Eigen::Vector3d r;
  Eigen::Matrix3d ja, jb;  // d r / d (x, y, theta) of a and of b
};

Residual Evaluate(const Experience& a, const Experience& b, const Link& l) {
  const double c = std::cos(a.theta_rad), s = std::sin(a.theta_rad);
  const double dx = b.x_m - a.x_m, dy = b.y_m - a.y_m;
  Residual out;
  out.r << c * dx + s * dy - l.distance_m * std::cos(l.heading_rad),
      -s * dx + c * dy - l.distance_m * std::sin(l.heading_rad),
      WrapAngle(b.theta_rad - a.theta_rad - l.facing_rad);
  out.ja << -c, -s, -s * dx + c * dy,  //
      s, -c, -c * dx - s * dy,         //
      0, 0, -1;
  out.jb << c, s, 0,  //
      -s, c, 0,       //
      0, 0, 1;
  return out;
}

Eigen::Matrix3d Omega(const LinkNoise& noise, const Link& l) {
  const std::array<double, 6> i = noise.Information(l.distance_m);
  Eigen::Matrix3d m;
  m << i[0], i[1], i[2], i[1], i[3], i[4], i[2], i[4], i[5];
  return m;
}

double Cost(const std::vector<Experience>& ex, const std::vector<Link>& links,
            const LinkNoise& noise) {
  double cost = 0.0;
  for (const Link& l : links) {
    const Eigen::Vector3d r = Evaluate(ex[l.from], ex[l.to], l).r;
    cost += r.dot(Omega(noise, l) * r);
  }
  return cost;
}

uint32_t Find(std::vector<uint32_t>& parent, uint32_t i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace

StatusOr<PoseGraphResult> OptimisePoseGraph(std::vector<Experience>* experiences,
                                            const std::vector<Link>& links, const LinkNoise& noise,
                                            int max_iterations) {
  std::vector<Experience>& ex = *experiences;
  const size_t n = ex.size();
  for (const Link& l : links) {
    if (l.from >= n || l.to >= n) return Status::Error("pose graph: a link's end does not exist");
  }
  if (!(noise.sigma_m > 0.0 || noise.sigma_m_per_m > 0.0) || !(noise.sigma_rad > 0.0)) {
    return Status::Error("pose graph: link noise must be positive");
  }
  // Gauge: the lowest id of every connected part stays where it is (the first experience for the
  // part that holds it).
  std::vector<uint32_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0u);
  for (const Link& l : links) {
    const uint32_t a = Find(parent, l.from), b = Find(parent, l.to);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  std::vector<int64_t> var(n, -1);
  int64_t unknowns = 0;
  for (uint32_t i = 0; i < n; ++i) {
    if (Find(parent, i) != i) var[i] = unknowns++;
  }
  PoseGraphResult result;
  result.initial_cost = Cost(ex, links, noise);
  result.final_cost = result.initial_cost;
  if (unknowns == 0) return result;

  const std::vector<Experience> before = ex;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
  std::vector<Eigen::Triplet<double>> triplets;
  for (int it = 0; it < max_iterations; ++it) {
    triplets.clear();
    triplets.reserve(links.size() * 36);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(3 * unknowns);
    for (const Link& l : links) {
      const Residual res = Evaluate(ex[l.from], ex[l.to], l);
      const Eigen::Matrix3d omega = Omega(noise, l);
      const int64_t va = var[l.from], vb = var[l.to];
      const Eigen::Matrix3d* j[2] = {&res.ja, &res.jb};
      const int64_t v[2] = {va, vb};
      for (int p = 0; p < 2; ++p) {
        if (v[p] < 0) continue;
        g.segment<3>(3 * v[p]) += j[p]->transpose() * omega * res.r;
        for (int q = 0; q < 2; ++q) {
          if (v[q] < 0) continue;
          const Eigen::Matrix3d block = j[p]->transpose() * omega * *j[q];
          for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 3; ++c) {
              triplets.emplace_back(3 * v[p] + r, 3 * v[q] + c, block(r, c));
            }
          }
        }
      }
    }
    Eigen::SparseMatrix<double> h(3 * unknowns, 3 * unknowns);
    h.setFromTriplets(triplets.begin(), triplets.end());
    if (it == 0) solver.analyzePattern(h);
    solver.factorize(h);
    if (solver.info() != Eigen::Success) {
      ex = before;
      return Status::Error("pose graph: the normal equations cannot be factorised");
    }
    const Eigen::VectorXd step = solver.solve(-g);
    if (solver.info() != Eigen::Success || !step.allFinite()) {
      ex = before;
      return Status::Error("pose graph: the normal equations cannot be solved");
    }
    for (uint32_t i = 0; i < n; ++i) {
      if (var[i] < 0) continue;
      ex[i].x_m += step[3 * var[i]];
      ex[i].y_m += step[3 * var[i] + 1];
      ex[i].theta_rad = WrapAngle(ex[i].theta_rad + step[3 * var[i] + 2]);
    }
    result.iterations = it + 1;
    if (step.lpNorm<Eigen::Infinity>() < 1e-9) break;
  }
  result.final_cost = Cost(ex, links, noise);
  return result;
}

}  // namespace ratslam
