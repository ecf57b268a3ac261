#include "session/evaluation_baselines.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <unordered_map>
#include <utility>

namespace ratslam::session {

using fabmap::Estimate;
using fabmap::EvaluationNode;

namespace {

// A scan as (AP id, mean RSSI) sorted by id; APs the map never heard get ids past the map's.
struct SparseScan {
  std::vector<std::pair<uint32_t, double>> aps;
};

class ApIds {
 public:
  uint32_t Id(const std::string& bssid, bool add) {
    auto it = ids_.find(bssid);
    if (it != ids_.end()) return it->second;
    const uint32_t id = static_cast<uint32_t>(ids_.size());
    if (add) ids_.emplace(bssid, id);
    return add ? id : kUnknown;
  }
  uint32_t size() const { return static_cast<uint32_t>(ids_.size()); }
  static constexpr uint32_t kUnknown = 0xffffffffu;

 private:
  std::unordered_map<std::string, uint32_t> ids_;
};

// Readings that are not finite are dropped; repeated BSSIDs averaged. Unknown APs (not in the
// map) keep only their contribution to the query's own norm, so they are returned apart.
SparseScan Sparse(const std::vector<WifiReading>& readings, ApIds* ids, bool add,
                  double* unknown_norm2) {
  std::map<uint32_t, std::pair<double, int>> merged;
  std::map<std::string, std::pair<double, int>> unknown;
  for (const WifiReading& r : readings) {
    if (!std::isfinite(r.rssi_dbm) || r.bssid.empty()) continue;
    const uint32_t id = ids->Id(r.bssid, add);
    auto& slot = id == ApIds::kUnknown ? unknown[r.bssid] : merged[id];
    slot.first += r.rssi_dbm;
    slot.second += 1;
  }
  SparseScan s;
  for (const auto& [id, sum] : merged) s.aps.push_back({id, sum.first / sum.second});
  if (unknown_norm2) {
    *unknown_norm2 = 0.0;
    for (const auto& [bssid, sum] : unknown) {
      const double d = sum.first / sum.second - kKnnNotHeardDbm;
      *unknown_norm2 += d * d;
    }
  }
  return s;
}

double Norm2(const SparseScan& s) {
  double n = 0.0;
  for (const auto& [id, rssi] : s.aps) n += (rssi - kKnnNotHeardDbm) * (rssi - kKnnNotHeardDbm);
  return n;
}

Estimate Vote(const std::vector<EvaluationNode>& map, const std::vector<uint32_t>& nodes,
              const std::vector<std::pair<double, uint32_t>>& nearest) {
  std::map<int, double> floor_weight;
  for (const auto& [d2, m] : nearest) {
    floor_weight[map[nodes[m]].floor] += 1.0 / std::max(std::sqrt(d2), 1e-3);
  }
  int floor = map[nodes[nearest.front().second]].floor;
  double best = floor_weight[floor];
  for (const auto& [f, w] : floor_weight) {
    if (w > best) best = w, floor = f;
  }
  Estimate e;
  e.located = true;
  e.floor = floor;
  double total = 0.0;
  for (const auto& [d2, m] : nearest) {
    const EvaluationNode& n = map[nodes[m]];
    if (n.floor != floor) continue;
    const double w = 1.0 / std::max(std::sqrt(d2), 1e-3);
    e.x_m += w * n.x_m;
    e.y_m += w * n.y_m;
    total += w;
  }
  e.x_m /= total;
  e.y_m /= total;
  return e;
}

}  // namespace

std::vector<Estimate> KnnEstimates(const std::vector<EvaluationNode>& map,
                                   const std::vector<EvaluationNode>& queries, int k) {
  std::vector<Estimate> out(queries.size());
  ApIds ids;
  std::vector<uint32_t> nodes;  // map index of each scan
  std::vector<SparseScan> scans;
  std::vector<double> norm2;
  for (size_t i = 0; i < map.size(); ++i) {
    if (!map[i].wifi) continue;
    nodes.push_back(static_cast<uint32_t>(i));
    scans.push_back(Sparse(*map[i].wifi, &ids, true, nullptr));
    norm2.push_back(Norm2(scans.back()));
  }
  if (scans.empty() || k < 1) return out;
  // Inverted index: per AP, the map scans that heard it and at what RSSI.
  std::vector<std::vector<std::pair<uint32_t, double>>> postings(ids.size());
  for (uint32_t m = 0; m < scans.size(); ++m) {
    for (const auto& [id, rssi] : scans[m].aps) postings[id].push_back({m, rssi});
  }
  const size_t keep = std::min(static_cast<size_t>(k), scans.size());
  std::vector<double> d2(scans.size());
  std::vector<std::pair<double, uint32_t>> order;
  for (size_t q = 0; q < queries.size(); ++q) {
    if (!queries[q].wifi) continue;
    double unknown = 0.0;
    const SparseScan s = Sparse(*queries[q].wifi, &ids, false, &unknown);
    // |q - m|^2 = |q|^2 + |m|^2 + sum over shared APs of (q-m)^2 - (q-F)^2 - (m-F)^2, with
    // every vector measured from the not-heard value F.
    const double own = Norm2(s) + unknown;
    for (size_t m = 0; m < scans.size(); ++m) d2[m] = own + norm2[m];
    for (const auto& [id, rssi] : s.aps) {
      const double qf = rssi - kKnnNotHeardDbm;
      for (const auto& [m, mr] : postings[id]) {
        const double mf = mr - kKnnNotHeardDbm;
        d2[m] += (rssi - mr) * (rssi - mr) - qf * qf - mf * mf;
      }
    }
    order.clear();
    for (uint32_t m = 0; m < scans.size(); ++m) order.push_back({std::max(0.0, d2[m]), m});
    std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(keep),
                      order.end());
    order.resize(keep);
    out[q] = Vote(map, nodes, order);
  }
  return out;
}

std::vector<Estimate> FingerprintEstimates(const std::vector<EvaluationNode>& map,
                                           const std::vector<EvaluationNode>& queries,
                                           const sensors::WifiMatcherOptions& options) {
  std::vector<Estimate> out(queries.size());
  sensors::WifiFingerprintMatcher matcher(options);
  std::vector<uint32_t> nodes;
  const auto pairs = [](const std::vector<WifiReading>& scan) {
    std::vector<std::pair<std::string, double>> readings;
    for (const WifiReading& r : scan) readings.push_back({r.bssid, r.rssi_dbm});
    return readings;
  };
  for (size_t i = 0; i < map.size(); ++i) {
    if (!map[i].wifi) continue;
    nodes.push_back(static_cast<uint32_t>(i));
    matcher.Add(matcher.MakeFingerprint(pairs(*map[i].wifi)));
  }
  for (size_t q = 0; q < queries.size(); ++q) {
    if (!queries[q].wifi || nodes.empty()) continue;
    const sensors::WifiMatch best = matcher.Best(matcher.MakeFingerprint(pairs(*queries[q].wifi)),
                                                 nullptr, options.match_threshold);
    if (best.id < 0) continue;
    const EvaluationNode& n = map[nodes[best.id]];
    out[q] = {true, n.x_m, n.y_m, n.floor};
  }
  return out;
}

}  // namespace ratslam::session
