#include "fusion/wifi_sequence/wifi_sequence.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/circular.h"
#include "common/median.h"

namespace ratslam::wifi_sequence {

bool WifiSequenceOptions::IsValid(std::string* error) const {
  if (!schema::CheckFields(*this, error)) return false;
  if (min_sequence_poses > max_sequence_poses) {
    if (error) *error = "min_sequence_poses: must not exceed max_sequence_poses";
    return false;
  }
  return true;
}

double SignalQuality(double rssi_dbm, double min_rssi_dbm) {
  return std::clamp(2.0 * (rssi_dbm - min_rssi_dbm), 0.0, 100.0);  // eq. 1
}

namespace {

// a += w * b, both ascending by AP index; `out` is scratch (swapped with a, so that its storage
// is reused from call to call).
void AddScaled(SparseSignal* a, const SparseSignal& b, double w, SparseSignal& out) {
  out.clear();
  size_t i = 0, j = 0;
  while (i < a->size() || j < b.size()) {
    if (j == b.size() || (i < a->size() && (*a)[i].first < b[j].first)) {
      out.push_back((*a)[i++]);
    } else if (i == a->size() || b[j].first < (*a)[i].first) {
      out.emplace_back(b[j].first, w * b[j].second);
      ++j;
    } else {
      out.emplace_back((*a)[i].first, (*a)[i].second + w * b[j].second);
      ++i;
      ++j;
    }
  }
  a->swap(out);
}

double Dot(const SparseSignal& a, const SparseSignal& b) {
  double sum = 0.0;
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (a[i].first < b[j].first) {
      ++i;
    } else if (b[j].first < a[i].first) {
      ++j;
    } else {
      sum += a[i++].second * b[j++].second;
    }
  }
  return sum;
}

bool Finite(const Pose2& p) {
  return std::isfinite(p.x_m) && std::isfinite(p.y_m) && std::isfinite(p.theta_rad);
}

}  // namespace

SmoothedSignalMatrix::SmoothedSignalMatrix(double tau_m, double cutoff_tau)
    : tau_m_(tau_m), cutoff_m_(cutoff_tau * tau_m) {}

double SmoothedSignalMatrix::Weight(double distance_m) const {
  return std::exp(-distance_m * distance_m / (2.0 * tau_m_ * tau_m_));  // eq. 3
}

void SmoothedSignalMatrix::Add(double travel_m, SparseSignal s) {
  const size_t n = raw_.size();
  travel_.push_back(travel_m);
  raw_.push_back(std::move(s));
  sum_.push_back(raw_.back());
  weight_sum_.push_back(1.0);
  norm_.push_back(-1.0);
  // Travel never decreases, so the poses within the cutoff are the newest ones.
  for (size_t t = n; t-- > 0;) {
    const double d = travel_m - travel_[t];
    if (d > cutoff_m_) break;
    const double w = Weight(d);
    AddScaled(&sum_[t], raw_[n], w, scratch_);
    weight_sum_[t] += w;
    norm_[t] = -1.0;
    AddScaled(&sum_[n], raw_[t], w, scratch_);
    weight_sum_[n] += w;
  }
}

SparseSignal SmoothedSignalMatrix::Smoothed(size_t t) const {
  SparseSignal out = sum_[t];
  for (auto& [ap, v] : out) v /= weight_sum_[t];  // eq. 4
  return out;
}

std::vector<std::pair<size_t, double>> SmoothedSignalMatrix::Weights(size_t t) const {
  std::vector<std::pair<size_t, double>> out;
  size_t first = t;
  while (first > 0 && travel_[t] - travel_[first - 1] <= cutoff_m_) --first;
  for (size_t i = first; i < travel_.size() && travel_[i] - travel_[t] <= cutoff_m_; ++i) {
    out.emplace_back(i, Weight(std::abs(travel_[t] - travel_[i])) / weight_sum_[t]);
  }
  return out;
}

double SmoothedSignalMatrix::Norm(size_t t) const {
  if (norm_[t] < 0.0) norm_[t] = std::sqrt(Dot(sum_[t], sum_[t]));
  return norm_[t];
}

double SmoothedSignalMatrix::Similarity(size_t i, size_t j) const {
  const double ni = Norm(i), nj = Norm(j);
  if (ni == 0.0 || nj == 0.0) return 0.0;
  return std::clamp(Dot(sum_[i], sum_[j]) / (ni * nj), 0.0, 1.0);
}

StatusOr<DpMatch> ContinuousDpMatch(const std::vector<double>& cost, size_t rows, size_t cols,
                                    double alpha) {
  if (rows == 0 || cols == 0 || cost.size() != rows * cols) {
    return Status::Error("continuous DP: the cost matrix is empty or not rows x cols");
  }
  for (double c : cost) {
    if (!std::isfinite(c) || c < 0.0) {
      return Status::Error("continuous DP: a cost is negative or not finite");
    }
  }
  constexpr double kInf = std::numeric_limits<double>::infinity();
  auto C = [&](size_t i, size_t j) { return cost[i * cols + j]; };
  std::vector<double> g(rows * cols, kInf);
  std::vector<uint8_t> step(rows * cols, 0);
  for (size_t j = 0; j < cols; ++j) g[j] = C(0, j);  // a path may start in any column
  auto G = [&](size_t i, size_t j) { return g[i * cols + j]; };
  for (size_t i = 1; i < rows; ++i) {
    for (size_t j = 0; j < cols; ++j) {
      // Eq. 5's five predecessors in its order; the first of equal costs wins.
      double best = kInf;
      uint8_t choice = 0;
      auto consider = [&](uint8_t k, double v) {
        if (v < best) {
          best = v;
          choice = k;
        }
      };
      if (j >= 3)
        consider(0, G(i - 1, j - 3) + C(i, j - 2) + alpha * C(i, j - 1) + alpha * C(i, j));
      if (j >= 2) consider(1, G(i - 1, j - 2) + C(i, j - 1) + alpha * C(i, j));
      if (j >= 1) consider(2, G(i - 1, j - 1) + C(i, j));
      if (j >= 1 && i >= 2) consider(3, G(i - 2, j - 1) + C(i - 1, j) + alpha * C(i, j));
      if (j >= 1 && i >= 3) {
        consider(4, G(i - 3, j - 1) + C(i - 2, j) + alpha * C(i - 1, j) + alpha * C(i, j));
      }
      g[i * cols + j] = best;
      step[i * cols + j] = choice;
    }
  }
  size_t end = 0;
  for (size_t j = 1; j < cols; ++j) {
    if (G(rows - 1, j) < G(rows - 1, end)) end = j;
  }
  if (!std::isfinite(G(rows - 1, end))) {
    return Status::Error("continuous DP: the past sequence is too short for the current one");
  }
  // Walk back, collecting the path's cells, then keep the cheapest cell of each row.
  std::vector<std::pair<size_t, size_t>> cells;
  size_t i = rows - 1, j = end;
  while (true) {
    cells.emplace_back(i, j);
    if (i == 0) break;
    switch (step[i * cols + j]) {
      case 0:
        cells.emplace_back(i, j - 1);
        cells.emplace_back(i, j - 2);
        i -= 1;
        j -= 3;
        break;
      case 1:
        cells.emplace_back(i, j - 1);
        i -= 1;
        j -= 2;
        break;
      case 2:
        i -= 1;
        j -= 1;
        break;
      case 3:
        cells.emplace_back(i - 1, j);
        i -= 2;
        j -= 1;
        break;
      default:
        cells.emplace_back(i - 1, j);
        cells.emplace_back(i - 2, j);
        i -= 3;
        j -= 1;
        break;
    }
  }
  DpMatch match;
  match.cost = G(rows - 1, end);
  match.pairs.resize(rows);
  std::vector<double> row_cost(rows, kInf);
  std::sort(cells.begin(), cells.end());
  for (const auto& [r, c] : cells) {
    if (C(r, c) < row_cost[r]) {
      row_cost[r] = C(r, c);
      match.pairs[r] = {static_cast<uint32_t>(r), static_cast<uint32_t>(c)};
    }
  }
  return match;
}

namespace {

double Residual(const RigidAlignment2D& t, const Point2& a, const Point2& b) {
  const double c = std::cos(t.rotation_rad), s = std::sin(t.rotation_rad);
  return std::hypot(c * a.x - s * a.y + t.translation_x_m - b.x,
                    s * a.x + c * a.y + t.translation_y_m - b.y);
}

}  // namespace

Verification VerifyCorrespondences(const std::vector<Point2>& current,
                                   const std::vector<Point2>& past,
                                   const WifiSequenceOptions& options) {
  Verification v;
  const size_t n = std::min(current.size(), past.size());
  v.inlier.assign(n, false);
  v.residual_m.assign(n, std::numeric_limits<double>::infinity());
  // Hypotheses: every pair far enough apart in both sequences superposes its midpoints and
  // turns the current pair's direction onto the past pair's (fig. 7, steps 1-2).
  size_t best_count = 0;
  double best_sum = 0.0;
  RigidAlignment2D best;
  const double sep = options.pair_min_separation_m;
  for (size_t k = 0; k < n; ++k) {
    for (size_t l = k + 1; l < n; ++l) {
      const double ax = current[l].x - current[k].x, ay = current[l].y - current[k].y;
      const double bx = past[l].x - past[k].x, by = past[l].y - past[k].y;
      if (std::hypot(ax, ay) < sep || std::hypot(bx, by) < sep) continue;
      RigidAlignment2D t;
      t.rotation_rad = WrapAngle(std::atan2(by, bx) - std::atan2(ay, ax));
      const double c = std::cos(t.rotation_rad), s = std::sin(t.rotation_rad);
      const double mx = 0.5 * (current[k].x + current[l].x),
                   my = 0.5 * (current[k].y + current[l].y);
      t.translation_x_m = 0.5 * (past[k].x + past[l].x) - (c * mx - s * my);
      t.translation_y_m = 0.5 * (past[k].y + past[l].y) - (s * mx + c * my);
      size_t count = 0;
      double sum = 0.0;
      for (size_t m = 0; m < n; ++m) {
        const double r = Residual(t, current[m], past[m]);  // step 3
        if (r <= options.inlier_distance_m) {
          ++count;
          sum += r;
        }
      }
      if (count > best_count || (count == best_count && count > 0 && sum < best_sum)) {
        best_count = count;
        best_sum = sum;
        best = t;
      }
    }
  }
  if (best_count < 2) return v;
  for (size_t m = 0; m < n; ++m)
    v.inlier[m] = Residual(best, current[m], past[m]) <= options.inlier_distance_m;
  // Least squares on the inliers, then the statistical test, until the set settles.
  for (int iteration = 0; iteration < 20; ++iteration) {
    std::vector<Point2> a, b;
    for (size_t m = 0; m < n; ++m) {
      if (!v.inlier[m]) continue;
      a.push_back(current[m]);
      b.push_back(past[m]);
    }
    const std::optional<RigidAlignment2D> fit = AlignRigid2D(a, b);
    if (!fit) break;
    v.transform = *fit;
    std::vector<double> inlier_residuals;
    for (size_t m = 0; m < n; ++m) {
      v.residual_m[m] = Residual(v.transform, current[m], past[m]);
      if (v.inlier[m]) inlier_residuals.push_back(v.residual_m[m]);
    }
    const double sigma = std::max(1.4826 * Median(inlier_residuals), options.residual_floor_m);
    bool changed = false;
    for (size_t m = 0; m < n; ++m) {
      const bool in =
          v.residual_m[m] <= std::min(options.outlier_sigmas * sigma, options.inlier_distance_m);
      changed |= in != v.inlier[m];
      v.inlier[m] = in;
    }
    if (!changed) break;
  }
  v.inliers = static_cast<size_t>(std::count(v.inlier.begin(), v.inlier.end(), true));
  if (v.inliers < 2) {
    v.inlier.assign(n, false);
    v.inliers = 0;
  }
  return v;
}

namespace {
const WifiSequenceOptions& Validated(const WifiSequenceOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("WifiSequenceOptions: " + error);
  return options;
}
}  // namespace

WifiSequenceLoopCloser::WifiSequenceLoopCloser(const WifiSequenceOptions& options)
    : options_(Validated(options)),
      matrix_(options.smoothing_tau_m, options.smoothing_cutoff_tau) {}

double WifiSequenceLoopCloser::Sigma(double travel_m) const {
  const double d = std::max(travel_m, 0.0);
  const double variance = options_.position_sigma_m * options_.position_sigma_m +
                          options_.distance_noise_m2_per_m * d +
                          options_.heading_noise_rad2_per_m * d * d * d / 3.0;
  return std::min(std::sqrt(variance), options_.max_sigma_m);
}

StatusOr<std::optional<SequenceLoop>> WifiSequenceLoopCloser::AddPose(
    const SequencePose& pose, const WifiScan& scan, const std::vector<Point2>& map_positions) {
  const size_t t = state_.poses.size();
  if (map_positions.size() != t + 1) {
    return Status::Error("Wi-Fi sequence: " + std::to_string(map_positions.size()) +
                         " map positions for " + std::to_string(t + 1) + " poses");
  }
  if (!std::isfinite(pose.time_s) || !std::isfinite(pose.travel_m) || !Finite(pose.odometry) ||
      !Finite(pose.anchor_offset) ||
      (pose.compass_heading_rad && !std::isfinite(*pose.compass_heading_rad))) {
    return Status::Error("Wi-Fi sequence: pose at t=" + std::to_string(pose.time_s) +
                         " has a non-finite time, travel or pose");
  }
  if (t > 0 && pose.travel_m < state_.poses.back().travel_m) {
    return Status::Error("Wi-Fi sequence: travel goes back at t=" + std::to_string(pose.time_s));
  }
  for (const Point2& p : map_positions) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      return Status::Error("Wi-Fi sequence: a map position is not finite");
    }
  }
  // Eq. 1 per AP; a BSSID heard twice in one scan keeps its strongest reading. Non-finite
  // readings are left out (the dataset reader refuses them; this is a library entry point).
  std::vector<std::pair<std::string, double>> heard;
  for (const WifiReading& r : scan.readings) {
    if (std::isfinite(r.rssi_dbm)) heard.emplace_back(r.bssid, r.rssi_dbm);
  }
  SparseSignal signal;
  for (const auto& [bssid, rssi] : heard) {
    auto [it, inserted] = ap_index_.emplace(bssid, static_cast<uint32_t>(state_.bssids.size()));
    if (inserted) state_.bssids.push_back(bssid);
    signal.emplace_back(it->second, SignalQuality(rssi, options_.min_rssi_dbm));
  }
  std::sort(signal.begin(), signal.end());
  SparseSignal unique;
  for (const auto& e : signal) {
    if (!unique.empty() && unique.back().first == e.first) {
      unique.back().second = std::max(unique.back().second, e.second);
    } else {
      unique.push_back(e);
    }
  }
  state_.poses.push_back(pose);
  PoseSignal saved;
  for (const auto& [ap, quality] : unique) {
    saved.aps.push_back(ap);
    saved.quality.push_back(quality);
  }
  state_.signals.push_back(std::move(saved));
  matrix_.Add(pose.travel_m, std::move(unique));

  // Section III-B.1: is the map's estimate of this pose inside a past pose's confidence circle?
  double best_ratio = std::numeric_limits<double>::infinity(), radius = 0.0;
  const Point2& here = map_positions[t];
  for (size_t i = 0; i < t; ++i) {
    const double travel = pose.travel_m - state_.poses[i].travel_m;
    if (travel < options_.min_loop_travel_m) break;
    const double r = options_.confidence_sigmas * Sigma(travel);
    const double ratio = std::hypot(here.x - map_positions[i].x, here.y - map_positions[i].y) / r;
    if (ratio < best_ratio) {
      best_ratio = ratio;
      radius = r;
    }
  }
  const bool revisiting = best_ratio <= 1.0;
  if (revisiting) {
    if (state_.open_sequence.empty()) state_.open_start_radius_m = radius;
    state_.open_sequence.push_back(static_cast<uint32_t>(t));
    state_.open_end_radius_m = radius;
    if (state_.open_sequence.size() >= static_cast<size_t>(options_.max_sequence_poses)) {
      std::optional<SequenceLoop> loop = Match(pose.time_s, /*ended=*/false);
      state_.open_continues = true;
      return loop;
    }
    return std::optional<SequenceLoop>();
  }
  if (state_.open_sequence.empty()) {
    state_.open_continues = false;
    return std::optional<SequenceLoop>();
  }
  std::optional<SequenceLoop> loop = Match(pose.time_s, /*ended=*/true);
  state_.open_continues = false;
  return loop;
}

std::optional<SequenceLoop> WifiSequenceLoopCloser::Flush(double time_s) {
  if (state_.open_sequence.empty()) return std::nullopt;
  std::optional<SequenceLoop> loop = Match(time_s, /*ended=*/true);
  state_.open_continues = false;
  return loop;
}

std::optional<SequenceLoop> WifiSequenceLoopCloser::Match(double time_s, bool ended) {
  std::vector<uint32_t> open;
  open.swap(state_.open_sequence);
  // Section III-B.3: the first and last poses may have no counterpart in the past; drop those
  // inside the first and last confidence circles (by travel). A sequence cut at
  // max_sequence_poses keeps the poses at the cut.
  const double first_travel = state_.poses[open.front()].travel_m;
  const double last_travel = state_.poses[open.back()].travel_m;
  std::vector<uint32_t> cs;
  for (uint32_t c : open) {
    const double travel = state_.poses[c].travel_m;
    if (!state_.open_continues && travel - first_travel < state_.open_start_radius_m) continue;
    if (ended && last_travel - travel < state_.open_end_radius_m) continue;
    cs.push_back(c);
  }
  if (cs.size() < static_cast<size_t>(options_.min_sequence_poses)) return std::nullopt;

  SequenceLoop loop;
  loop.id = static_cast<uint32_t>(state_.loops.size());
  loop.time_s = time_s;
  loop.current_sequence = cs;
  // The PS: poses far enough behind the whole CS with enough similarity to some CS pose. The CS
  // rows are made dense over the APs they hear so that each past pose costs one pass over its
  // own APs for all CS poses at once.
  const double boundary = state_.poses[open.front()].travel_m - options_.min_loop_travel_m;
  const size_t aps = state_.bssids.size();
  std::vector<double> dense(aps * cs.size(), 0.0);  // [ap][cs]
  for (size_t r = 0; r < cs.size(); ++r) {
    const double norm = matrix_.Norm(cs[r]);
    if (norm == 0.0) continue;
    for (const auto& [ap, v] : matrix_.Unnormalised(cs[r])) dense[ap * cs.size() + r] = v / norm;
  }
  std::vector<double> similarity_row(cs.size());
  std::vector<std::vector<double>> ps_similarity;  // per PS pose, per CS pose
  for (size_t p = 0; p < open.front() && state_.poses[p].travel_m <= boundary; ++p) {
    const double norm = matrix_.Norm(p);
    if (norm == 0.0) continue;
    std::fill(similarity_row.begin(), similarity_row.end(), 0.0);
    for (const auto& [ap, v] : matrix_.Unnormalised(p)) {
      const double* column = &dense[ap * cs.size()];
      const double w = v / norm;
      for (size_t r = 0; r < cs.size(); ++r) similarity_row[r] += w * column[r];
    }
    if (*std::max_element(similarity_row.begin(), similarity_row.end()) >=
        options_.past_similarity) {
      loop.past_sequence.push_back(static_cast<uint32_t>(p));
      ps_similarity.push_back(similarity_row);
    }
  }
  const size_t rows = cs.size(), cols = loop.past_sequence.size();
  if (cols < static_cast<size_t>(options_.min_sequence_poses)) {
    loop.outcome = "past sequence too short";
    state_.loops.push_back(loop);
    return loop;
  }
  // The PS may hold several past visits (a route walked many times): each visit (a run of PS
  // poses without a travel gap above past_split_m) is spotted by continuous DP on its own, and
  // the visit whose correspondences verify best (most inliers, then least DP cost) is kept. One
  // DP over all visits would hop from one visit to a later one part way.
  std::vector<std::pair<size_t, size_t>> visits;  // [first, last) columns
  for (size_t c = 0; c < cols; ++c) {
    const bool split = c == 0 || state_.poses[loop.past_sequence[c]].travel_m -
                                         state_.poses[loop.past_sequence[c - 1]].travel_m >
                                     options_.past_split_m;
    if (split) visits.emplace_back(c, c);
    visits.back().second = c + 1;
  }
  bool matched = false, compass_refused = false;
  for (const auto& [first, last] : visits) {
    for (const bool reversed : {false, true}) {
      if (reversed && !options_.match_reversed) continue;
      const size_t width = last - first;
      // Column c of this DP: the visit in time order, or backwards (walked the other way).
      auto column = [&, first = first, last = last](size_t c) {
        return reversed ? last - 1 - c : first + c;
      };
      std::vector<double> cost(rows * width);
      for (size_t r = 0; r < rows; ++r) {
        for (size_t c = 0; c < width; ++c) {
          const double sim = std::clamp(ps_similarity[column(c)][r], 0.0, 1.0);
          cost[r * width + c] = 1.0 / std::max(sim, options_.min_similarity);
        }
      }
      StatusOr<DpMatch> dp = ContinuousDpMatch(cost, rows, width, options_.dp_alpha);
      if (!dp.ok()) continue;
      std::vector<SequenceCorrespondence> pairs;
      std::vector<Point2> a, b;
      for (const DpCorrespondence& pair : dp.value().pairs) {
        SequenceCorrespondence corr;
        corr.current_pose = cs[pair.current];
        corr.past_pose = loop.past_sequence[column(pair.past)];
        corr.similarity = std::clamp(ps_similarity[column(pair.past)][pair.current], 0.0, 1.0);
        pairs.push_back(corr);
        const Pose2& pc = state_.poses[corr.current_pose].odometry;
        const Pose2& pp = state_.poses[corr.past_pose].odometry;
        a.push_back({pc.x_m, pc.y_m});
        b.push_back({pp.x_m, pp.y_m});
      }
      Verification v = VerifyCorrespondences(a, b, options_);
      if (!CompassAgrees(pairs, v)) {
        compass_refused = true;
        continue;
      }
      if (matched && (v.inliers < loop.inliers ||
                      (v.inliers == loop.inliers && dp.value().cost >= loop.dp_cost))) {
        continue;
      }
      matched = true;
      for (size_t k = 0; k < pairs.size(); ++k) {
        pairs[k].inlier = v.inlier[k];
        pairs[k].residual_m = v.residual_m[k];
      }
      loop.correspondences = std::move(pairs);
      loop.dp_cost = dp.value().cost;
      loop.inliers = static_cast<uint32_t>(v.inliers);
      loop.transform = {v.transform.translation_x_m, v.transform.translation_y_m,
                        v.transform.rotation_rad};
      loop.reversed = reversed;
    }
  }
  if (!matched) {
    loop.outcome = compass_refused ? "fit rotation disagrees with the compass" : "no DP path";
    state_.loops.push_back(loop);
    return loop;
  }
  const size_t inliers = loop.inliers;
  loop.accepted =
      inliers >= static_cast<size_t>(options_.min_inliers) &&
      static_cast<double>(inliers) >= options_.min_inlier_fraction * static_cast<double>(rows);
  loop.outcome = loop.accepted ? "accepted" : "too few consistent correspondences";
  state_.loops.push_back(loop);
  return loop;
}

bool WifiSequenceLoopCloser::CompassAgrees(const std::vector<SequenceCorrespondence>& pairs,
                                           const Verification& v) const {
  // Each sequence's odometry frame is turned from the world by the circular mean of compass
  // minus odometry heading over its verified poses; the fit must turn the current frame onto the
  // past one by the difference.
  double cs_sin = 0, cs_cos = 0, ps_sin = 0, ps_cos = 0;
  for (size_t k = 0; k < pairs.size(); ++k) {
    if (!v.inlier[k]) continue;
    const SequencePose& c = state_.poses[pairs[k].current_pose];
    const SequencePose& p = state_.poses[pairs[k].past_pose];
    if (!c.compass_heading_rad || !p.compass_heading_rad) return true;  // nothing to compare
    cs_sin += std::sin(*c.compass_heading_rad - c.odometry.theta_rad);
    cs_cos += std::cos(*c.compass_heading_rad - c.odometry.theta_rad);
    ps_sin += std::sin(*p.compass_heading_rad - p.odometry.theta_rad);
    ps_cos += std::cos(*p.compass_heading_rad - p.odometry.theta_rad);
  }
  if (v.inliers == 0) return true;
  const double expected = std::atan2(cs_sin, cs_cos) - std::atan2(ps_sin, ps_cos);
  return std::abs(WrapAngle(v.transform.rotation_rad - expected)) <=
         options_.max_compass_disagreement_rad;
}

Pose2 WifiSequenceLoopCloser::RelativePose(const SequenceLoop& loop, uint32_t current,
                                           uint32_t past) const {
  const Pose2& c = state_.poses[current].odometry;
  const Pose2& p = state_.poses[past].odometry;
  const Pose2 moved = Compose({loop.transform.x_m, loop.transform.y_m, loop.transform.theta_rad},
                              c.x_m, c.y_m, c.theta_rad);
  const double dx = moved.x_m - p.x_m, dy = moved.y_m - p.y_m;
  const double cp = std::cos(p.theta_rad), sp = std::sin(p.theta_rad);
  return {cp * dx + sp * dy, -sp * dx + cp * dy, WrapAngle(moved.theta_rad - p.theta_rad)};
}

Status WifiSequenceLoopCloser::SetState(State state) {
  const size_t n = state.poses.size();
  auto fail = [](const std::string& what) {
    return Status::Error("saved Wi-Fi sequence state: " + what);
  };
  if (state.signals.size() != n) return fail("signals and poses differ in number");
  std::map<std::string, uint32_t> index;
  for (size_t i = 0; i < state.bssids.size(); ++i) {
    if (!index.emplace(state.bssids[i], static_cast<uint32_t>(i)).second) {
      return fail("BSSID " + state.bssids[i] + " appears twice");
    }
  }
  for (size_t i = 0; i < n; ++i) {
    const SequencePose& p = state.poses[i];
    if (!std::isfinite(p.time_s) || !std::isfinite(p.travel_m) || !Finite(p.odometry) ||
        !Finite(p.anchor_offset) || p.anchor < -1 ||
        (p.compass_heading_rad && !std::isfinite(*p.compass_heading_rad)) ||
        (i > 0 && p.travel_m < state.poses[i - 1].travel_m)) {
      return fail("pose " + std::to_string(i) + " is not finite or goes back");
    }
    const PoseSignal& s = state.signals[i];
    if (s.aps.size() != s.quality.size()) {
      return fail("signal of pose " + std::to_string(i) +
                  " has APs and values differing in number");
    }
    for (size_t k = 0; k < s.aps.size(); ++k) {
      if (s.aps[k] >= state.bssids.size() || !(s.quality[k] >= 0.0 && s.quality[k] <= 100.0) ||
          (k > 0 && s.aps[k] <= s.aps[k - 1])) {
        return fail("signal of pose " + std::to_string(i) + " is out of range");
      }
    }
  }
  auto pose_ok = [n](uint32_t id) { return id < n; };
  for (uint32_t c : state.open_sequence) {
    if (!pose_ok(c)) return fail("the open sequence refers to a pose that does not exist");
  }
  if (!std::isfinite(state.open_start_radius_m) || !std::isfinite(state.open_end_radius_m)) {
    return fail("open sequence radius is not finite");
  }
  for (const SequenceLoop& l : state.loops) {
    for (uint32_t c : l.current_sequence) {
      if (!pose_ok(c)) return fail("a loop refers to a pose that does not exist");
    }
    for (uint32_t c : l.past_sequence) {
      if (!pose_ok(c)) return fail("a loop refers to a pose that does not exist");
    }
    for (const SequenceCorrespondence& c : l.correspondences) {
      if (!pose_ok(c.current_pose) || !pose_ok(c.past_pose)) {
        return fail("a loop refers to a pose that does not exist");
      }
    }
    if (!Finite(l.transform)) return fail("a loop transform is not finite");
  }
  SmoothedSignalMatrix matrix(options_.smoothing_tau_m, options_.smoothing_cutoff_tau);
  for (size_t i = 0; i < n; ++i) {
    SparseSignal signal;
    for (size_t k = 0; k < state.signals[i].aps.size(); ++k) {
      signal.emplace_back(state.signals[i].aps[k], state.signals[i].quality[k]);
    }
    matrix.Add(state.poses[i].travel_m, std::move(signal));
  }
  state_ = std::move(state);
  ap_index_ = std::move(index);
  matrix_ = std::move(matrix);
  return Status::Ok();
}

}  // namespace ratslam::wifi_sequence
