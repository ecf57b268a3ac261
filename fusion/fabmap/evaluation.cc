#include "fusion/fabmap/evaluation.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <system_error>
#include <tuple>
#include <utility>

namespace ratslam::fabmap {

std::string ToString(SplitUnit unit) {
  switch (unit) {
    case SplitUnit::kNode:
      return "node";
    case SplitUnit::kSession:
      return "session";
    case SplitUnit::kFirstSession:
      return "first_session";
    case SplitUnit::kPosition:
      return "position";
  }
  return "?";
}

StatusOr<SplitUnit> SplitUnitFromString(const std::string& name) {
  if (name == "node") return SplitUnit::kNode;
  if (name == "session") return SplitUnit::kSession;
  if (name == "first_session") return SplitUnit::kFirstSession;
  if (name == "position") return SplitUnit::kPosition;
  return Status::Error("unknown split '" + name +
                       "' (expected node, session, first_session or position)");
}

std::string ToString(AnswerRule rule) {
  switch (rule) {
    case AnswerRule::kBestPlace:
      return "best_place";
    case AnswerRule::kPosterior:
      return "posterior";
  }
  return "?";
}

StatusOr<AnswerRule> AnswerRuleFromString(const std::string& name) {
  if (name == "best_place") return AnswerRule::kBestPlace;
  if (name == "posterior") return AnswerRule::kPosterior;
  return Status::Error("unknown answer '" + name + "' (expected best_place or posterior)");
}

std::string ToString(NewPlaceRule rule) {
  switch (rule) {
    case NewPlaceRule::kNearRecall:
      return "near_recall";
    case NewPlaceRule::kYouden:
      return "youden";
  }
  return "?";
}

StatusOr<NewPlaceRule> NewPlaceRuleFromString(const std::string& name) {
  if (name == "near_recall") return NewPlaceRule::kNearRecall;
  if (name == "youden") return NewPlaceRule::kYouden;
  return Status::Error("unknown new_place_rule '" + name + "' (expected near_recall or youden)");
}

bool EvaluationOptions::IsValid(std::string* error) const {
  if (!schema::CheckFields(*this, error)) return false;
  if (far_place_m < near_place_m) {
    if (error) *error = "far_place_m must be at least near_place_m";
    return false;
  }
  return true;
}

namespace {

// The highest threshold (-inf or a midpoint between distinct scores) at which at most
// `allowed` of the ascending `scores` are rejected (score <= t).
double HighestThresholdRejectingAtMost(const std::vector<double>& scores, size_t allowed) {
  size_t j = std::min(allowed, scores.size());
  while (j > 0 && j < scores.size() && scores[j - 1] == scores[j]) --j;  // never split a tie
  if (j == 0) return -std::numeric_limits<double>::infinity();
  if (j == scores.size() || !std::isfinite(scores[j - 1]) || !std::isfinite(scores[j])) {
    return scores[j - 1];
  }
  return scores[j - 1] + 0.5 * (scores[j] - scores[j - 1]);
}

NewPlaceThreshold NearRecallThreshold(const std::vector<double>& log_odds,
                                      const std::vector<bool>& near, double near_recall) {
  NewPlaceThreshold result;
  std::vector<double> near_scores, far_scores;
  for (size_t i = 0; i < log_odds.size() && i < near.size(); ++i) {
    const double v =
        std::isnan(log_odds[i]) ? -std::numeric_limits<double>::infinity() : log_odds[i];
    (near[i] ? near_scores : far_scores).push_back(v);
  }
  result.near = near_scores.size();
  result.far = far_scores.size();
  if (near_scores.empty() || !(near_recall > 0.0)) return result;
  std::sort(near_scores.begin(), near_scores.end());
  const double n = static_cast<double>(near_scores.size());
  // The 1e-9 keeps (1 - 0.95) * 20 = 1 from rounding down to 0.
  const auto allowed =
      static_cast<size_t>(std::floor((1.0 - std::min(near_recall, 1.0)) * n + 1e-9));
  const double t = HighestThresholdRejectingAtMost(near_scores, allowed);
  result.log_odds = t;
  const auto accepted =
      std::count_if(near_scores.begin(), near_scores.end(), [t](double v) { return v > t; });
  const auto rejected =
      std::count_if(far_scores.begin(), far_scores.end(), [t](double v) { return !(v > t); });
  result.near_accepted = static_cast<double>(accepted) / n;
  result.far_rejected =
      far_scores.empty() ? 0.0 : static_cast<double>(rejected) / static_cast<double>(result.far);
  result.calibrated = true;
  return result;
}

NewPlaceThreshold YoudenThreshold(const std::vector<double>& log_odds,
                                  const std::vector<bool>& near) {
  NewPlaceThreshold result;
  std::vector<std::pair<double, bool>> scored;
  for (size_t i = 0; i < log_odds.size() && i < near.size(); ++i) {
    const double v =
        std::isnan(log_odds[i]) ? -std::numeric_limits<double>::infinity() : log_odds[i];
    scored.push_back({v, near[i]});
    ++(near[i] ? result.near : result.far);
  }
  if (result.near == 0 || result.far == 0) return result;
  std::sort(scored.begin(), scored.end());
  // Sweep t upwards: below every finite score first, then past each run of equal scores.
  const double lowest = -std::numeric_limits<double>::infinity();
  size_t far_rejected = 0, near_rejected = 0, i = 0;
  while (i < scored.size() && scored[i].first == lowest) {
    ++(scored[i].second ? near_rejected : far_rejected);
    ++i;
  }
  auto j_of = [&] {
    return 1.0 - static_cast<double>(near_rejected) / static_cast<double>(result.near) +
           static_cast<double>(far_rejected) / static_cast<double>(result.far) - 1.0;
  };
  double best_j = j_of();
  double best_t = lowest;
  size_t best_far = far_rejected, best_near = near_rejected;
  while (i < scored.size()) {
    const double v = scored[i].first;
    while (i < scored.size() && scored[i].first == v) {
      ++(scored[i].second ? near_rejected : far_rejected);
      ++i;
    }
    const double j = j_of();
    if (j > best_j) {
      best_j = j;
      best_t = i < scored.size() && std::isfinite(v) && std::isfinite(scored[i].first)
                   ? v + 0.5 * (scored[i].first - v)
                   : v;
      best_far = far_rejected;
      best_near = near_rejected;
    }
  }
  // "Accept every finite score": the largest threshold below them all is -inf itself, which
  // rejects exactly the nodes without a mapped place.
  result.log_odds = best_t;
  result.near_accepted = 1.0 - static_cast<double>(best_near) / static_cast<double>(result.near);
  result.far_rejected = static_cast<double>(best_far) / static_cast<double>(result.far);
  result.calibrated = true;
  return result;
}

}  // namespace

NewPlaceThreshold LearnNewPlaceThreshold(const std::vector<double>& log_odds,
                                         const std::vector<bool>& near, NewPlaceRule rule,
                                         double near_recall) {
  return rule == NewPlaceRule::kYouden ? YoudenThreshold(log_odds, near)
                                       : NearRecallThreshold(log_odds, near, near_recall);
}

MapDistanceReport ByMapDistance(const EvaluationMetrics& metrics,
                                const std::vector<double>& nearest_m, double near_m, double far_m) {
  MapDistanceReport report;
  report.near_m = near_m;
  report.far_m = far_m;
  for (size_t i = 0; i < metrics.errors_m.size() && i < nearest_m.size(); ++i) {
    MapDistanceGroup* group = nearest_m[i] <= near_m ? &report.near
                              : nearest_m[i] > far_m ? &report.far
                                                     : nullptr;
    if (!group) continue;
    const double e = metrics.errors_m[i];
    ++group->queries;
    if (std::isnan(e)) {
      group->rejection_rate += 1.0;
    } else if (std::isinf(e)) {
      group->floor_mistake_rate += 1.0;
    } else {
      group->located_rate += 1.0;
    }
  }
  for (MapDistanceGroup* g : {&report.near, &report.far}) {
    if (g->queries == 0) continue;
    const double n = static_cast<double>(g->queries);
    g->rejection_rate /= n;
    g->floor_mistake_rate /= n;
    g->located_rate /= n;
  }
  return report;
}

SplitNodes SplitEvaluationNodes(const std::vector<EvaluationNode>& nodes,
                                const EvaluationOptions& options) {
  // Groups (sessions by id, or positions) in the order of their first node: a session whose nodes
  // interleave in time with another's (UJIIndoorLoc's users and phones took turns) stays whole
  // on one side, as do the captures at one position.
  std::map<std::tuple<int, double, double>, size_t> index_of;
  auto key = [&](const EvaluationNode& n) {
    return options.split == SplitUnit::kPosition ? std::tuple(n.floor, n.x_m, n.y_m)
                                                 : std::tuple(n.session, 0.0, 0.0);
  };
  for (const auto& n : nodes) index_of.emplace(key(n), index_of.size());
  const bool by_group =
      options.split == SplitUnit::kSession || options.split == SplitUnit::kPosition;
  const std::vector<bool> split =
      InterleavedSplit(by_group ? index_of.size() : nodes.size(), options.map_fraction);
  SplitNodes out;
  for (size_t i = 0; i < nodes.size(); ++i) {
    const size_t group = index_of.at(key(nodes[i]));
    const bool in_map = options.split == SplitUnit::kFirstSession ? group == 0
                        : by_group                                ? split[group]
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

Estimate PosteriorEstimate(const std::vector<EvaluationNode>& map,
                           const std::vector<double>& place_probability, int places,
                           double temperature) {
  // The most probable places, highest first (ties: the lower index).
  std::vector<std::pair<double, size_t>> top;
  const size_t n = std::min(map.size(), place_probability.size());
  for (size_t i = 0; i < n; ++i) {
    if (place_probability[i] > 0.0) top.push_back({place_probability[i], i});
  }
  Estimate e;
  if (top.empty() || places < 1) return e;
  const size_t keep = std::min(top.size(), static_cast<size_t>(places));
  std::partial_sort(top.begin(), top.begin() + static_cast<std::ptrdiff_t>(keep), top.end(),
                    [](const auto& a, const auto& b) {
                      return a.first > b.first || (a.first == b.first && a.second < b.second);
                    });
  top.resize(keep);
  // Weights relative to the best place, in logs, so that posteriors far below it stay finite.
  const double best_log = std::log(top.front().first);
  for (auto& [p, i] : top) p = std::exp((std::log(p) - best_log) / temperature);
  // Building first, then a floor in it; ties go to the more probable place's.
  const auto vote = [&](auto&& label, auto&& in_race) {
    std::map<int, double> total;
    for (const auto& [w, i] : top) {
      if (in_race(map[i])) total[label(map[i])] += w;
    }
    int winner = 0;
    double most = -1.0;
    for (const auto& [w, i] : top) {  // most probable first: the first of equals wins
      if (in_race(map[i]) && total[label(map[i])] > most) {
        most = total[label(map[i])];
        winner = label(map[i]);
      }
    }
    return winner;
  };
  const int building = vote([](const EvaluationNode& m) { return m.building; },
                            [](const EvaluationNode&) { return true; });
  e.floor = vote([](const EvaluationNode& m) { return m.floor; },
                 [&](const EvaluationNode& m) { return m.building == building; });
  double total = 0.0;
  for (const auto& [w, i] : top) {
    if (map[i].building != building || map[i].floor != e.floor) continue;
    e.x_m += w * map[i].x_m;
    e.y_m += w * map[i].y_m;
    total += w;
  }
  e.x_m /= total;
  e.y_m /= total;
  e.located = true;
  return e;
}

EvaluationMetrics ComputeMetrics(const std::vector<EvaluationNode>& map,
                                 const std::vector<EvaluationNode>& queries,
                                 const std::vector<int64_t>& matches,
                                 const std::vector<double>& distances_m) {
  std::vector<Estimate> estimates(queries.size());
  for (size_t i = 0; i < queries.size() && i < matches.size(); ++i) {
    const int64_t match = matches[i];
    if (match < 0 || static_cast<size_t>(match) >= map.size()) continue;
    estimates[i] = {true, map[match].x_m, map[match].y_m, map[match].floor};
  }
  return ComputeMetrics(queries, estimates, distances_m);
}

EvaluationMetrics ComputeMetrics(const std::vector<EvaluationNode>& queries,
                                 const std::vector<Estimate>& estimates,
                                 const std::vector<double>& distances_m) {
  EvaluationMetrics m;
  m.queries = queries.size();
  m.distances_m = distances_m;
  m.correct_within.assign(distances_m.size(), 0.0);
  m.misplaced_beyond.assign(distances_m.size(), 0.0);
  size_t rejected = 0, floor_mistakes = 0;
  for (size_t i = 0; i < queries.size(); ++i) {
    const Estimate e = i < estimates.size() ? estimates[i] : Estimate{};
    double error = std::numeric_limits<double>::quiet_NaN();
    if (!e.located) {
      ++rejected;
    } else if (e.floor != queries[i].floor) {
      ++floor_mistakes;
      error = std::numeric_limits<double>::infinity();
    } else {
      error = std::hypot(e.x_m - queries[i].x_m, e.y_m - queries[i].y_m);
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

std::vector<double> NearestPlaceDistances(const std::vector<EvaluationNode>& map,
                                          const std::vector<EvaluationNode>& queries,
                                          double reach_m) {
  std::vector<double> nearest(queries.size(), std::numeric_limits<double>::infinity());
  // Map places by floor, sorted by x, so each query scans only the x window of the reach.
  std::map<int, std::vector<std::pair<double, double>>> by_floor;
  for (const EvaluationNode& n : map) by_floor[n.floor].push_back({n.x_m, n.y_m});
  for (auto& [floor, places] : by_floor) std::sort(places.begin(), places.end());
  for (size_t i = 0; i < queries.size(); ++i) {
    const EvaluationNode& q = queries[i];
    const auto it = by_floor.find(q.floor);
    if (it == by_floor.end()) continue;
    const auto& places = it->second;
    double best = std::numeric_limits<double>::infinity();
    auto p = std::lower_bound(places.begin(), places.end(),
                              std::make_pair(q.x_m - reach_m, -std::numeric_limits<double>::max()));
    for (; p != places.end() && p->first <= q.x_m + reach_m; ++p) {
      best = std::min(best, std::hypot(p->first - q.x_m, p->second - q.y_m));
    }
    if (best <= reach_m) nearest[i] = best;
  }
  return nearest;
}

std::vector<double> NearestPlaceWithin(const std::vector<EvaluationNode>& map,
                                       const std::vector<EvaluationNode>& queries,
                                       const std::vector<double>& distances_m) {
  std::vector<double> within(distances_m.size(), 0.0);
  if (queries.empty()) return within;
  const double reach =
      distances_m.empty() ? 0.0 : *std::max_element(distances_m.begin(), distances_m.end());
  for (double best : NearestPlaceDistances(map, queries, reach)) {
    for (size_t k = 0; k < distances_m.size(); ++k) within[k] += best <= distances_m[k];
  }
  for (double& w : within) w /= static_cast<double>(queries.size());
  return within;
}

double ShareOnMappedFloors(const std::vector<EvaluationNode>& map,
                           const std::vector<EvaluationNode>& queries) {
  if (queries.empty()) return 0.0;
  std::set<int> floors;
  for (const EvaluationNode& n : map) floors.insert(n.floor);
  size_t on = 0;
  for (const EvaluationNode& q : queries) on += floors.count(q.floor);
  return static_cast<double>(on) / static_cast<double>(queries.size());
}

double FloorAccuracy(const std::vector<EvaluationNode>& queries,
                     const std::vector<std::optional<int>>& floors) {
  if (queries.empty() || floors.size() != queries.size()) return 0.0;
  size_t right = 0;
  for (size_t i = 0; i < queries.size(); ++i) right += floors[i] == queries[i].floor;
  return static_cast<double>(right) / static_cast<double>(queries.size());
}

std::vector<PrecisionRecallPoint> PrecisionRecallCurve(const std::vector<double>& best_probability,
                                                       const std::vector<double>& best_error_m,
                                                       const std::vector<double>& nearest_m,
                                                       const std::vector<double>& distances_m) {
  const size_t n = best_probability.size();
  const size_t nd = distances_m.size();
  std::vector<size_t> localisable(nd, 0);
  for (size_t i = 0; i < n && i < nearest_m.size(); ++i) {
    for (size_t k = 0; k < nd; ++k) localisable[k] += nearest_m[i] <= distances_m[k];
  }
  std::vector<size_t> order;
  for (size_t i = 0; i < n; ++i) {
    if (!std::isnan(best_probability[i])) order.push_back(i);
  }
  // Highest posterior first; equal posteriors are accepted together (one point per value).
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return best_probability[a] > best_probability[b]; });
  std::vector<PrecisionRecallPoint> curve;
  std::vector<size_t> correct(nd, 0);
  for (size_t j = 0; j < order.size(); ++j) {
    const size_t i = order[j];
    for (size_t k = 0; k < nd; ++k) correct[k] += best_error_m[i] <= distances_m[k];
    if (j + 1 < order.size() && best_probability[order[j + 1]] == best_probability[i]) continue;
    PrecisionRecallPoint p;
    p.threshold = best_probability[i];
    p.accepted = j + 1;
    p.correct = correct;
    for (size_t k = 0; k < nd; ++k) {
      p.precision.push_back(static_cast<double>(correct[k]) / static_cast<double>(p.accepted));
      p.recall.push_back(localisable[k] == 0 ? 0.0
                                             : static_cast<double>(correct[k]) /
                                                   static_cast<double>(localisable[k]));
    }
    curve.push_back(std::move(p));
  }
  return curve;
}

}  // namespace ratslam::fabmap
