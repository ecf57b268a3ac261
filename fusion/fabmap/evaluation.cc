#include "fusion/fabmap/evaluation.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>
#include <system_error>

namespace ratslam::fabmap {

std::string ToString(SplitUnit unit) {
  switch (unit) {
    case SplitUnit::kNode:
      return "node";
    case SplitUnit::kSession:
      return "session";
    case SplitUnit::kFirstSession:
      return "first_session";
  }
  return "?";
}

StatusOr<SplitUnit> SplitUnitFromString(const std::string& name) {
  if (name == "node") return SplitUnit::kNode;
  if (name == "session") return SplitUnit::kSession;
  if (name == "first_session") return SplitUnit::kFirstSession;
  return Status::Error("unknown split '" + name + "' (expected node, session or first_session)");
}

bool EvaluationOptions::IsValid(std::string* error) const {
  return schema::CheckFields(*this, error);
}

SplitNodes SplitEvaluationNodes(const std::vector<EvaluationNode>& nodes,
                                const EvaluationOptions& options) {
  std::vector<int> sessions;
  for (const auto& n : nodes) {
    if (sessions.empty() || sessions.back() != n.session) sessions.push_back(n.session);
  }
  const bool by_session = options.split == SplitUnit::kSession;
  const std::vector<bool> split =
      InterleavedSplit(by_session ? sessions.size() : nodes.size(), options.map_fraction);
  SplitNodes out;
  size_t session_index = 0;
  for (size_t i = 0; i < nodes.size(); ++i) {
    if (i > 0 && nodes[i].session != nodes[i - 1].session) ++session_index;
    const bool in_map = options.split == SplitUnit::kFirstSession ? session_index == 0
                        : by_session                              ? split[session_index]
                                                                  : split[i];
    (in_map ? out.map : out.queries).push_back(nodes[i]);
  }
  return out;
}

std::vector<bool> InterleavedSplit(size_t count, double map_fraction) {
  std::vector<bool> in_map(count);
  for (size_t i = 0; i < count; ++i) {
    in_map[i] = std::floor((i + 1) * map_fraction) > std::floor(i * map_fraction);
  }
  return in_map;
}

EvaluationMetrics ComputeMetrics(const std::vector<EvaluationNode>& map,
                                 const std::vector<EvaluationNode>& queries,
                                 const std::vector<int64_t>& matches,
                                 const std::vector<double>& distances_m) {
  EvaluationMetrics m;
  m.queries = queries.size();
  m.distances_m = distances_m;
  m.correct_within.assign(distances_m.size(), 0.0);
  m.misplaced_beyond.assign(distances_m.size(), 0.0);
  size_t rejected = 0, floor_mistakes = 0;
  for (size_t i = 0; i < queries.size(); ++i) {
    const int64_t match = i < matches.size() ? matches[i] : -1;
    double error = std::numeric_limits<double>::quiet_NaN();
    if (match < 0 || static_cast<size_t>(match) >= map.size()) {
      ++rejected;
    } else if (map[match].floor != queries[i].floor) {
      ++floor_mistakes;
      error = std::numeric_limits<double>::infinity();
    } else {
      error = std::hypot(map[match].x_m - queries[i].x_m, map[match].y_m - queries[i].y_m);
    }
    m.errors_m.push_back(error);
    for (size_t k = 0; k < distances_m.size(); ++k) {
      if (error <= distances_m[k]) m.correct_within[k] += 1.0;
      if (error > distances_m[k]) m.misplaced_beyond[k] += 1.0;  // false for NaN
    }
  }
  if (m.queries > 0) {
    const double n = static_cast<double>(m.queries);
    for (double& r : m.correct_within) r /= n;
    for (double& r : m.misplaced_beyond) r /= n;
    m.rejection_rate = rejected / n;
    m.floor_mistake_rate = floor_mistakes / n;
  }
  return m;
}

}  // namespace ratslam::fabmap
