#include "sensors/wifi_fingerprint_matcher.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

namespace ratslam {

bool WifiMatcherOptions::IsValid(std::string* error) const {
  return schema::CheckFields(*this, error);
}

WifiFingerprintMatcher::WifiFingerprintMatcher(const WifiMatcherOptions& options)
    : options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("WifiMatcherOptions: " + error);
}

double WifiFingerprintMatcher::Penalty2(double rssi_dbm) const {
  const double p = options_.penalty_per_dbm * std::max(0.0, rssi_dbm - options_.penalty_floor_dbm);
  return p * p;
}

Fingerprint WifiFingerprintMatcher::MakeFingerprint(
    const std::vector<std::pair<std::string, double>>& readings) {
  std::map<uint32_t, std::pair<double, int>> merged;  // id -> (sum, count), ordered by id
  for (const auto& [bssid, rssi] : readings) {
    if (!std::isfinite(rssi) || rssi < options_.min_rssi_dbm || bssid.empty()) continue;
    auto [it, inserted] = bssid_ids_.emplace(bssid, static_cast<uint32_t>(state_.bssids.size()));
    if (inserted) {
      state_.bssids.push_back(bssid);
      postings_.emplace_back();
    }
    auto& slot = merged[it->second];
    slot.first += rssi;
    slot.second += 1;
  }
  Fingerprint f;
  for (const auto& [id, sum_count] : merged) {
    f.ap_ids.push_back(id);
    f.rssi_dbm.push_back(static_cast<float>(sum_count.first / sum_count.second));
  }
  return f;
}

double WifiFingerprintMatcher::Weight(const Fingerprint& q, const Fingerprint& j) const {
  const double two_sigma2 = 2.0 * options_.kernel_variance_dbm2;
  size_t a = 0, b = 0;
  int common = 0;
  double hit = 0.0, diff = 0.0, extra = 0.0, miss = 0.0;
  while (a < q.ap_ids.size() || b < j.ap_ids.size()) {
    if (b == j.ap_ids.size() || (a < q.ap_ids.size() && q.ap_ids[a] < j.ap_ids[b])) {
      extra += Penalty2(q.rssi_dbm[a++]);
    } else if (a == q.ap_ids.size() || j.ap_ids[b] < q.ap_ids[a]) {
      miss += Penalty2(j.rssi_dbm[b++]);
    } else {
      const double d = q.rssi_dbm[a++] - j.rssi_dbm[b++];
      hit += d * d;
      diff += d;
      ++common;
    }
  }
  if (common == 0) return 0.0;
  if (options_.offset_invariant) hit = std::max(0.0, hit - diff * diff / common);
  const double e = static_cast<double>(q.ap_ids.size()) - common;
  const double m = static_cast<double>(j.ap_ids.size()) - common;
  // w_hit^(1/H): the H-th root of a product of exponentials is the exponential of the mean.
  return std::exp(-hit / (two_sigma2 * common) - extra / two_sigma2 - miss / two_sigma2) * common /
         (common + e + m);
}

template <typename Visit>
void WifiFingerprintMatcher::ForEachCandidate(const Fingerprint& query, Visit&& visit) const {
  if (options_.offset_invariant) {
    ForEachCandidateOf<true>(query, std::forward<Visit>(visit));
  } else {
    ForEachCandidateOf<false>(query, std::forward<Visit>(visit));
  }
}

template <bool kOffsetInvariant, typename Visit>
void WifiFingerprintMatcher::ForEachCandidateOf(const Fingerprint& query, Visit&& visit) const {
  const size_t n = state_.fingerprints.size();
  if (common_.size() < n) {
    common_.resize(n, 0);
    hit_sum_.resize(n, 0.0);
    if (kOffsetInvariant) diff_sum_.resize(n, 0.0);
    extra_common_.resize(n, 0.0);
    miss_common_.resize(n, 0.0);
  }
  touched_.clear();
  double extra_total = 0.0;
  for (size_t a = 0; a < query.ap_ids.size(); ++a) {
    const double s = query.rssi_dbm[a];
    const double extra = Penalty2(s);
    extra_total += extra;
    if (query.ap_ids[a] >= postings_.size()) continue;
    for (const Posting& p : postings_[query.ap_ids[a]]) {
      if (common_[p.fingerprint]++ == 0) touched_.push_back(p.fingerprint);
      const double d = s - p.rssi_dbm;
      hit_sum_[p.fingerprint] += d * d;
      if constexpr (kOffsetInvariant) diff_sum_[p.fingerprint] += d;
      extra_common_[p.fingerprint] += extra;
      miss_common_[p.fingerprint] += p.penalty2;
    }
  }
  const double two_sigma2 = 2.0 * options_.kernel_variance_dbm2;
  const double query_size = static_cast<double>(query.ap_ids.size());
  for (uint32_t id : touched_) {
    const double h = common_[id];
    const double e = query_size - h;
    const double m = static_cast<double>(state_.fingerprints[id].ap_ids.size()) - h;
    const double extra = std::max(0.0, extra_total - extra_common_[id]);
    const double miss = std::max(0.0, miss_penalty_total_[id] - miss_common_[id]);
    double hit = hit_sum_[id];
    if constexpr (kOffsetInvariant) hit = std::max(0.0, hit - diff_sum_[id] * diff_sum_[id] / h);
    visit(id, std::exp(-hit / (two_sigma2 * h) - extra / two_sigma2 - miss / two_sigma2) * h /
                  (h + e + m));
    common_[id] = 0;
    hit_sum_[id] = extra_common_[id] = miss_common_[id] = 0.0;
    if constexpr (kOffsetInvariant) diff_sum_[id] = 0.0;
  }
}

std::vector<double> WifiFingerprintMatcher::Weights(const Fingerprint& query) const {
  std::vector<double> weights(state_.fingerprints.size(), 0.0);
  ForEachCandidate(query, [&weights](uint32_t id, double w) { weights[id] = w; });
  return weights;
}

WifiMatch WifiFingerprintMatcher::Best(const Fingerprint& query) const {
  WifiMatch best;
  ForEachCandidate(query, [&best](uint32_t id, double w) {
    // Ties go to the older template, independent of the order the index visits them in.
    if (w > best.weight ||
        (w == best.weight && best.id >= 0 && id < static_cast<uint32_t>(best.id))) {
      best.weight = w;
      best.id = static_cast<int32_t>(id);
    }
  });
  return best;
}

void WifiFingerprintMatcher::Index(uint32_t id) {
  const Fingerprint& f = state_.fingerprints[id];
  double miss_total = 0.0;
  for (size_t a = 0; a < f.ap_ids.size(); ++a) {
    if (f.ap_ids[a] >= postings_.size()) postings_.resize(f.ap_ids[a] + 1);
    const double penalty2 = Penalty2(f.rssi_dbm[a]);
    postings_[f.ap_ids[a]].push_back({id, f.rssi_dbm[a], penalty2});
    miss_total += penalty2;
  }
  miss_penalty_total_.push_back(miss_total);
}

uint32_t WifiFingerprintMatcher::Add(const Fingerprint& fingerprint) {
  const uint32_t id = static_cast<uint32_t>(state_.fingerprints.size());
  state_.fingerprints.push_back(fingerprint);
  Index(id);
  return id;
}

Status WifiFingerprintMatcher::SetState(State state) {
  for (const Fingerprint& f : state.fingerprints) {
    if (f.ap_ids.size() != f.rssi_dbm.size()) {
      return Status::Error("Wi-Fi matcher state: fingerprint sizes differ");
    }
    for (size_t a = 0; a < f.ap_ids.size(); ++a) {
      if (f.ap_ids[a] >= state.bssids.size() || (a > 0 && f.ap_ids[a] <= f.ap_ids[a - 1])) {
        return Status::Error("Wi-Fi matcher state: AP ids out of range or unsorted");
      }
    }
  }
  state_ = std::move(state);
  bssid_ids_.clear();
  for (uint32_t i = 0; i < state_.bssids.size(); ++i) bssid_ids_[state_.bssids[i]] = i;
  postings_.assign(state_.bssids.size(), {});
  miss_penalty_total_.clear();
  for (uint32_t id = 0; id < state_.fingerprints.size(); ++id) Index(id);
  return Status::Ok();
}

}  // namespace ratslam
