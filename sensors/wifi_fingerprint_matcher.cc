#include "sensors/wifi_fingerprint_matcher.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <stdexcept>
#include <utility>

namespace ratslam::sensors {

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
      if (Counts(q.ap_ids[a])) extra += Penalty2(q.rssi_dbm[a]);
      ++a;
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
  const double e = static_cast<double>(CountedSize(q)) - common;
  const double m = static_cast<double>(j.ap_ids.size()) - common;
  // w_hit^(1/H): the H-th root of a product of exponentials is the exponential of the mean.
  return std::exp(-hit / (two_sigma2 * common) - extra / two_sigma2 - miss / two_sigma2) * common /
         (common + e + m);
}

template <bool kOffsetInvariant, typename Finish, typename Budget>
void WifiFingerprintMatcher::Scan(const Fingerprint& query, Finish&& finish,
                                  Budget&& budget) const {
  const uint32_t n = size();
  // The query's indexed APs, with their penalty and a cursor into their posting list.
  lists_.clear();
  double extra_total = 0.0;
  for (size_t a = 0; a < query.ap_ids.size(); ++a) {
    const double extra = Penalty2(query.rssi_dbm[a]);
    if (Counts(query.ap_ids[a])) extra_total += extra;
    if (query.ap_ids[a] >= postings_.size()) continue;
    const std::vector<Posting>& list = postings_[query.ap_ids[a]];
    if (!list.empty()) {
      lists_.push_back(
          {list.data(), list.data(), list.data() + list.size(), query.rssi_dbm[a], extra});
    }
  }
  // When the query's lists hold many postings per stored fingerprint (one building: all share
  // APs), fingerprints go in blocks of kBlock ids, so that the block's sums stay in the L1 cache
  // while every list adds to them (posting lists are in id order); otherwise (a campus) in one
  // block. Within a fingerprint the sums run over the query's APs in order, as the pairwise
  // formula does, so the blocks change no result.
  size_t total = 0;
  for (const ListCursor& list : lists_) total += static_cast<size_t>(list.end - list.next);
  const uint32_t block = total * 4 >= n ? kBlock : std::max<uint32_t>(n, 1);
  if (acc_.size() < block) acc_.resize(block);
  if (kOffsetInvariant && diff_.size() < block) diff_.resize(block, 0.0);
  // The lists by the query AP's penalty, largest first, for the pruning below (sorted when
  // first needed: a scan in one block, or with no budget, never prunes).
  by_penalty_.clear();
  for (uint32_t base = 0; base < n && total > 0; base += block) {
    const uint32_t limit = base + block;
    const uint32_t slots = std::min(block, n - base);
    size_t count = 0;
    for (ListCursor& list : lists_) {
      list.stop =
          limit >= n
              ? list.end
              : std::lower_bound(list.next, list.end, limit,
                                 [](const Posting& p, uint32_t id) { return p.fingerprint < id; });
      count += static_cast<size_t>(list.stop - list.next);
    }
    if (count == 0) continue;
    // A block most of whose fingerprints are touched (one building: all share APs) is cheaper to
    // scan whole afterwards than to track with a branch per posting; a sparse one (a campus) is
    // the other way round.
    const bool dense = count * 4 >= slots;
    touched_.clear();
    auto add = [&](const ListCursor& list, const Posting& p, uint32_t slot) {
      Accumulator& acc = acc_[slot];
      ++acc.common;
      const double d = list.s - p.rssi_dbm;
      if constexpr (kOffsetInvariant) diff_[slot] += d;
      acc.hit += d * d;
      acc.penalty_common += list.extra + p.penalty2;
    };
    // Pruning (max-score): a fingerprint missing every one of the query's k most penalised APs
    // has a penalty of at least the sum of their P^2 (eq. 4). Once that sum exceeds the budget
    // (the largest penalty a fingerprint may have and still win, from the best so far), only the
    // fingerprints on those k "essential" lists are scored; the others are left out, exactly.
    // Their sums still run over all the query's lists in order, so scored fingerprints get the
    // same weight to the bit.
    const double allowed = budget();
    if (by_penalty_.empty() && allowed < std::numeric_limits<double>::infinity()) {
      by_penalty_.resize(lists_.size());
      std::iota(by_penalty_.begin(), by_penalty_.end(), uint32_t{0});
      std::stable_sort(by_penalty_.begin(), by_penalty_.end(), [this](uint32_t a, uint32_t b) {
        return lists_[a].extra > lists_[b].extra;
      });
    }
    size_t essential = 0;
    double essential_sum = 0.0;
    while (essential < by_penalty_.size() && !(essential_sum > allowed)) {
      essential_sum += lists_[by_penalty_[essential++]].extra;
    }
    if (essential_sum > allowed && essential < lists_.size()) {
      if (marked_.size() < block) marked_.resize(block, 0);
      for (size_t k = 0; k < essential; ++k) {
        const ListCursor& list = lists_[by_penalty_[k]];
        for (const Posting* p = list.next; p != list.stop; ++p) {
          const uint32_t slot = p->fingerprint - base;
          if (!dense && !marked_[slot]) touched_.push_back(slot);
          marked_[slot] = 1;
        }
      }
      for (ListCursor& list : lists_) {
        for (const Posting* p = list.next; p != list.stop; ++p) {
          const uint32_t slot = p->fingerprint - base;
          if (marked_[slot]) add(list, *p, slot);
        }
        list.next = list.stop;
      }
      if (dense) {
        std::fill(marked_.begin(), marked_.begin() + slots, uint8_t{0});
      } else {
        for (uint32_t slot : touched_) marked_[slot] = 0;
      }
    } else {
      for (ListCursor& list : lists_) {
        for (const Posting* p = list.next; p != list.stop; ++p) {
          const uint32_t slot = p->fingerprint - base;
          if (!dense && acc_[slot].common == 0) touched_.push_back(slot);
          add(list, *p, slot);
        }
        list.next = list.stop;
      }
    }
    auto complete = [&](uint32_t slot) {
      Accumulator& acc = acc_[slot];
      Candidate c;
      c.id = base + slot;
      c.h = acc.common;
      c.hit = acc.hit;
      if constexpr (kOffsetInvariant) {
        c.hit = std::max(0.0, c.hit - diff_[slot] * diff_[slot] / c.h);
        diff_[slot] = 0.0;
      }
      c.penalty = std::max(0.0, (extra_total + miss_penalty_total_[c.id]) - acc.penalty_common);
      finish(c);
      acc = Accumulator();
    };
    if (dense) {
      for (uint32_t slot = 0; slot < slots; ++slot) {
        if (acc_[slot].common != 0) complete(slot);
      }
    } else {
      for (uint32_t slot : touched_) complete(slot);
    }
  }
}

double WifiFingerprintMatcher::Exponent(const Candidate& c) const {
  const double two_sigma2 = 2.0 * options_.kernel_variance_dbm2;
  return -c.hit / (two_sigma2 * c.h) - c.penalty / two_sigma2;
}

double WifiFingerprintMatcher::CandidateWeight(const Candidate& c, double exponent,
                                               size_t query_size) const {
  const double e = static_cast<double>(query_size) - c.h;
  const double m = static_cast<double>(sizes_[c.id]) - c.h;
  return std::exp(exponent) * c.h / (c.h + e + m);
}

template <typename Visit>
void WifiFingerprintMatcher::ForEachCandidate(const Fingerprint& query, Visit&& visit) const {
  const size_t query_size = CountedSize(query);
  auto finish = [&](const Candidate& c) {
    visit(c.id, CandidateWeight(c, Exponent(c), query_size));
  };
  const auto unbounded = [] { return std::numeric_limits<double>::infinity(); };
  if (options_.offset_invariant) {
    Scan<true>(query, finish, unbounded);
  } else {
    Scan<false>(query, finish, unbounded);
  }
}

std::vector<double> WifiFingerprintMatcher::Weights(const Fingerprint& query) const {
  std::vector<double> weights(state_.fingerprints.size(), 0.0);
  ForEachCandidate(query, [&weights](uint32_t id, double w) { weights[id] = w; });
  return weights;
}

WifiMatch WifiFingerprintMatcher::Best(const Fingerprint& query,
                                       const std::vector<uint8_t>* allowed,
                                       double min_weight) const {
  WifiMatch best;
  // w = exp(x) * H / (H + E + M) <= exp(x): a fingerprint whose exponent x is below log(best)
  // (or log(min_weight)) cannot win, and its exp is skipped. The margin of 1e-9 covers the
  // rounding of exp, of the log and of the product (each within a few ulps), so the answer is
  // the exhaustive one.
  const bool floor = min_weight > 0.0;  // false for NaN too
  double skip_below =
      floor ? std::log(min_weight) - 1e-9 : -std::numeric_limits<double>::infinity();
  const size_t query_size = CountedSize(query);
  const double inv_two_sigma2 = 1.0 / (2.0 * options_.kernel_variance_dbm2);
  auto finish = [&](const Candidate& c) {
    if (allowed && !(*allowed)[c.id]) return;
    // The penalties alone (hit >= 0) bound x from above: most candidates stop here, before the
    // divisions. The margin covers the reciprocal's rounding.
    if (!(-c.penalty * inv_two_sigma2 >= skip_below - 1e-9)) return;
    const double x = Exponent(c);
    if (!(x >= skip_below)) return;
    const uint32_t id = c.id;
    const double w = CandidateWeight(c, x, query_size);
    if (floor && !(w >= min_weight)) return;
    // Ties go to the older template, independent of the order the index visits them in.
    if (w > best.weight ||
        (w == best.weight && best.id >= 0 && id < static_cast<uint32_t>(best.id))) {
      best.weight = w;
      best.id = static_cast<int32_t>(id);
      if (w > 0.0) skip_below = std::log(w) - 1e-9;
    }
  };
  // The budget of the pruning: a candidate is scored in full only if -penalty / (2 sigma^2) >=
  // skip_below - 1e-9 (above), so one whose penalty exceeds this cannot win. The relative margin
  // covers the rounding of the penalty's sums.
  const auto budget = [&] { return (1e-9 - skip_below) / inv_two_sigma2 * (1.0 + 1e-9) + 1e-9; };
  if (options_.offset_invariant) {
    Scan<true>(query, finish, budget);
  } else {
    Scan<false>(query, finish, budget);
  }
  return best;
}

size_t WifiFingerprintMatcher::CountedSize(const Fingerprint& query) const {
  if (!options_.unmapped_aps_neutral) return query.ap_ids.size();
  size_t n = 0;
  for (uint32_t id : query.ap_ids) n += Mapped(id);
  return n;
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
  sizes_.push_back(static_cast<uint32_t>(f.ap_ids.size()));
}

uint32_t WifiFingerprintMatcher::Add(const Fingerprint& fingerprint) {
  const uint32_t id = static_cast<uint32_t>(state_.fingerprints.size());
  state_.fingerprints.push_back(fingerprint);
  Index(id);
  return id;
}

WifiFingerprintMatcher::Update WifiFingerprintMatcher::FollowRevisit(uint32_t id,
                                                                     const Fingerprint& scan) {
  Fingerprint& f = state_.fingerprints.at(id);
  Fingerprint merged;
  Update update;
  auto position = [id](std::vector<Posting>& list) {
    return std::lower_bound(list.begin(), list.end(), id,
                            [](const Posting& p, uint32_t i) { return p.fingerprint < i; });
  };
  size_t a = 0, b = 0;
  while (a < f.ap_ids.size() || b < scan.ap_ids.size()) {
    if (b == scan.ap_ids.size() || (a < f.ap_ids.size() && f.ap_ids[a] <= scan.ap_ids[b])) {
      const bool heard = b < scan.ap_ids.size() && f.ap_ids[a] == scan.ap_ids[b];
      if (heard) ++b;  // held and heard: keeps the template's RSSI
      if (!heard && f.rssi_dbm[a] > options_.penalty_floor_dbm) {
        // Held strongly enough to cost eq. 5, and not heard on a sure revisit: gone.
        std::vector<Posting>& list = postings_[f.ap_ids[a]];
        list.erase(position(list));
        ++update.dropped;
        ++a;
        continue;
      }
      merged.ap_ids.push_back(f.ap_ids[a]);
      merged.rssi_dbm.push_back(f.rssi_dbm[a++]);
      continue;
    }
    const uint32_t ap = scan.ap_ids[b];
    const float rssi = scan.rssi_dbm[b++];
    merged.ap_ids.push_back(ap);
    merged.rssi_dbm.push_back(rssi);
    // The AP's posting list stays in fingerprint-id order (the scan relies on it).
    if (ap >= postings_.size()) postings_.resize(ap + 1);
    std::vector<Posting>& list = postings_[ap];
    list.insert(position(list), Posting{id, rssi, Penalty2(rssi)});
    ++update.added;
  }
  f = std::move(merged);
  // Summed in AP order as Index does, so a restored matcher (SetState re-indexes) agrees to the
  // bit.
  double miss_total = 0.0;
  for (float rssi : f.rssi_dbm) miss_total += Penalty2(rssi);
  miss_penalty_total_[id] = miss_total;
  sizes_[id] = static_cast<uint32_t>(f.ap_ids.size());
  return update;
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
  sizes_.clear();
  for (uint32_t id = 0; id < state_.fingerprints.size(); ++id) Index(id);
  return Status::Ok();
}

}  // namespace ratslam::sensors
