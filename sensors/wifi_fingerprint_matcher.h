// Wi-Fi fingerprint matching of the Wi-Fi RatSLAM paper (section III-B, eqs. 3-6), after Weyn's
// model. A fingerprint is a set of (BSSID, RSSI dBm). Against a stored fingerprint j:
//   w_hit   = prod over the H common APs of exp(-(s - s_j)^2 / (2 sigma^2))           (eq. 3)
//   w_extra = prod over the E APs only in the query of exp(-P(s)^2 / (2 sigma^2))      (eq. 4)
//   w_miss  = prod over the M APs only in j of exp(-P(s_j)^2 / (2 sigma^2))            (eq. 5)
//   w       = w_hit^(1/H) * w_extra * w_miss * H / (H + E + M)                         (eq. 6)
// The paper takes the penalty P from Weyn without stating it; ours grows linearly with how far
// the AP's RSSI is above a floor, P(s) = penalty_per_dbm * max(0, s - penalty_floor_dbm), so a
// strong AP that should be there and is not is strong evidence against a match and an AP near
// the sensitivity floor (often missed by a scan) is almost none.
//
// With `unmapped_aps_neutral`, a query's APs that no stored fingerprint holds (access points
// installed since the map was made) are left out of eq. 4 and of E: every stored fingerprint
// misses them alike, so they cannot tell places apart, and on long-term data (months of AP
// changes) their penalty only pushes known places below t_wifi. APs the map holds but the query
// does not hear still count in eq. 5.
//
// With `offset_invariant`, the hit term of eq. 3 compares the RSSI differences around their
// mean over the H common APs, sum (d - mean d)^2 instead of sum d^2: a constant offset between
// the two scans (two phones that read several dB apart: 6-8 dB between the IPIN 2023 phones)
// then costs nothing. The penalties of eqs. 4-5 keep absolute RSSI.
//
// Fingerprints are indexed by BSSID: a query touches only the stored fingerprints that share an
// AP with it; the per-fingerprint totals of penalties are precomputed, so extra and missing APs
// cost nothing beyond the shared ones. Best, once it has met a good match, scores only the
// fingerprints holding one of the query's most penalised APs (max-score pruning: any other has
// an eq. 4 penalty that already rules it out), with the same answer as the exhaustive scan. A
// caller that only acts on a match of at least t_wifi (the front ends) passes it as a floor, and
// the pruning then starts with the first block of ids instead of after the first good match.
#ifndef RATSLAM_SENSORS_WIFI_FINGERPRINT_MATCHER_H_
#define RATSLAM_SENSORS_WIFI_FINGERPRINT_MATCHER_H_

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "common/schema.h"
#include "common/status.h"

namespace ratslam::sensors {

struct WifiMatcherOptions {
  double kernel_variance_dbm2 = 20.0;  // sigma^2 of eqs. 3-5 (Chiou et al., the paper's value)
  double penalty_floor_dbm = -90.0;    // an extra or missing AP at or below this costs nothing
  double penalty_per_dbm = 0.1;        // P(s) = penalty_per_dbm * max(0, s - penalty_floor_dbm)
  double match_threshold = 0.25;       // t_wifi: smallest weight w that is a match
  double min_rssi_dbm = -100.0;        // readings weaker than this are dropped from scans
  bool offset_invariant = false;       // eq. 3 on differences around their mean (see above)
  bool unmapped_aps_neutral = false;   // APs no stored fingerprint holds: not in eq. 4 nor in E

  bool IsValid(std::string* error) const;

  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("kernel_variance_dbm2", kernel_variance_dbm2,
      "sigma^2 of the Gaussian kernels of eqs. 3-5, dBm^2 (paper: 20)",
      schema::Unit("dBm^2").Positive());
    v("penalty_floor_dbm", penalty_floor_dbm,
      "extra or missing APs at or below this RSSI carry no penalty", schema::Unit("dBm"));
    v("penalty_per_dbm", penalty_per_dbm,
      "penalty P(s) = penalty_per_dbm * max(0, s - penalty_floor_dbm) for eqs. 4-5",
      schema::Unit("1/dBm").NonNegative());
    v("match_threshold", match_threshold, "t_wifi: smallest weight w (eq. 6) that is a match",
      schema::Unit("").Within(0, 1));
    v("min_rssi_dbm", min_rssi_dbm, "readings weaker than this are ignored", schema::Unit("dBm"));
    v("offset_invariant", offset_invariant,
      "eq. 3 compares RSSI differences around their mean over the common APs, so a constant "
      "offset between phones costs nothing",
      schema::Any());
    v("unmapped_aps_neutral", unmapped_aps_neutral,
      "a query's APs that no stored fingerprint holds (new since the map was made) take no part "
      "in eq. 4's penalty nor in E of eq. 6: they say the world changed, not which place this is",
      schema::Any());
  }
};

// A scan reduced to unique APs (by interned BSSID id), sorted by id.
struct Fingerprint {
  std::vector<uint32_t> ap_ids;
  std::vector<float> rssi_dbm;
  bool empty() const { return ap_ids.empty(); }
};

struct WifiMatch {
  int32_t id = -1;      // -1: nothing stored shares an AP
  double weight = 0.0;  // eq. 6
};

class WifiFingerprintMatcher {
 public:
  struct State {
    std::vector<std::string> bssids;  // interned, index = AP id
    std::vector<Fingerprint> fingerprints;
  };

  // `options` must be valid; throws std::invalid_argument otherwise.
  explicit WifiFingerprintMatcher(const WifiMatcherOptions& options);

  // Interns BSSIDs (new ones get new ids) and merges repeated APs by averaging their RSSI.
  // Readings that are not finite or below min_rssi_dbm are dropped.
  Fingerprint MakeFingerprint(const std::vector<std::pair<std::string, double>>& readings);

  // The weight of eq. 6 between two fingerprints.
  double Weight(const Fingerprint& query, const Fingerprint& stored) const;
  // Weights against every stored fingerprint, by id (0 where no AP is shared).
  std::vector<double> Weights(const Fingerprint& query) const;
  // The stored fingerprint with the largest weight (eq. 9); with `allowed` (one flag per stored
  // fingerprint), the largest among those whose flag is set. With `min_weight` > 0, the largest
  // only if it is at least `min_weight` ({-1, 0} otherwise): what a caller holding t_wifi needs,
  // and faster, since the pruning below has its budget from the first block on.
  WifiMatch Best(const Fingerprint& query, const std::vector<uint8_t>* allowed = nullptr,
                 double min_weight = 0.0) const;

  // Stores a fingerprint (possibly empty: a template with no Wi-Fi); returns its id.
  uint32_t Add(const Fingerprint& fingerprint);
  // A revisit the caller is sure of (`scan` matched stored fingerprint `id`): the fingerprint
  // follows the access points that changed since it was stored. The scan's APs it lacks are added
  // at the RSSI heard; its APs the scan did not hear although stored above penalty_floor_dbm
  // (strong enough to cost eq. 5) are dropped; APs both hold keep the stored RSSI. `id` must be
  // < size().
  struct Update {
    size_t added = 0, dropped = 0;
  };
  Update FollowRevisit(uint32_t id, const Fingerprint& scan);
  uint32_t size() const { return static_cast<uint32_t>(state_.fingerprints.size()); }
  const WifiMatcherOptions& options() const { return options_; }
  const State& state() const { return state_; }
  Status SetState(State state);

 private:
  struct Posting {
    uint32_t fingerprint;
    float rssi_dbm;
    double penalty2;  // P(rssi)^2, precomputed for eq. 5
  };
  double Penalty2(double rssi_dbm) const;
  // Whether some stored fingerprint holds AP `id`.
  bool Mapped(uint32_t id) const { return id < postings_.size() && !postings_[id].empty(); }
  // Whether the query's AP takes part in eq. 4 and E (every AP, or with unmapped_aps_neutral
  // the mapped ones), and how many of the query's APs do.
  bool Counts(uint32_t id) const { return !options_.unmapped_aps_neutral || Mapped(id); }
  size_t CountedSize(const Fingerprint& query) const;
  // Per stored fingerprint, sums over the APs it shares with the query (one record, so a posting
  // costs one cache line).
  // The two penalty sums share one field (the caller needs only their total): one store fewer
  // per posting, and stores are what bound the scan (bench/wifi_matching_benchmark: 11 % faster).
  struct alignas(32) Accumulator {
    double hit = 0.0;             // sum of d^2, d the RSSI difference
    double penalty_common = 0.0;  // sum over the shared APs of the query's P^2 and the stored one's
    uint32_t common = 0;
  };
  // A stored fingerprint sharing H APs with the query: the sums of eqs. 3-5 (hit around the mean
  // with offset_invariant).
  struct Candidate {
    uint32_t id;
    double h, hit, penalty;  // penalty: the sums of eqs. 4 and 5
  };
  // Visits every stored fingerprint sharing an AP with the query, block by block of ids:
  // finish(candidate). Compiled once per hit term so the plain one pays nothing for the other.
  // budget(): the largest penalty (sum of eqs. 4-5) a fingerprint may have and still matter
  // (infinity: every one does); asked once per block, so it may fall as the scan goes on.
  template <bool kOffsetInvariant, typename Finish, typename Budget>
  void Scan(const Fingerprint& query, Finish&& finish, Budget&& budget) const;
  // The exponent of eq. 6: the log of w_hit^(1/H) w_extra w_miss.
  double Exponent(const Candidate& c) const;
  // w of eq. 6 from that exponent: exp(x) H / (H + E + M).
  double CandidateWeight(const Candidate& c, double exponent, size_t query_size) const;
  // Visits every stored fingerprint sharing an AP with the query: visit(id, weight).
  template <typename Visit>
  void ForEachCandidate(const Fingerprint& query, Visit&& visit) const;
  void Index(uint32_t id);

  WifiMatcherOptions options_;
  State state_;
  std::unordered_map<std::string, uint32_t> bssid_ids_;
  std::vector<std::vector<Posting>> postings_;  // by AP id
  std::vector<double> miss_penalty_total_;      // by fingerprint: sum of P(s)^2 of all its APs
  std::vector<uint32_t> sizes_;                 // by fingerprint: its number of APs
  // Scratch for queries: sums per fingerprint of the block being scanned (zero outside a scan),
  // the query's posting lists.
  static constexpr uint32_t kBlock = 512;
  mutable std::vector<Accumulator> acc_;
  mutable std::vector<double> diff_;          // sum of d (offset_invariant)
  mutable std::vector<uint32_t> touched_;     // of a sparse block
  mutable std::vector<uint8_t> marked_;       // on an essential list (zero outside a scan)
  mutable std::vector<uint32_t> by_penalty_;  // indices into lists_, largest penalty first
  struct ListCursor {
    const Posting* next;
    const Posting* stop;  // the first posting past the block being scanned
    const Posting* end;
    double s, extra;
  };
  mutable std::vector<ListCursor> lists_;
};

}  // namespace ratslam::sensors

#endif  // RATSLAM_SENSORS_WIFI_FINGERPRINT_MATCHER_H_
