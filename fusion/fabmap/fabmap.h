// FABMAP place recognition (Cummins and Newman 2008, 2011; the fusion paper's section 2).
//
// Observation likelihood: each place keeps whether it saw each word; a word's existence e_q at a
// place is inferred through the detector model p(z|e), and observations follow the Chow-Liu tree.
// Per word, p(z_q | e_q, z_parent) combines the two as in Cummins and Newman (2008):
//   p(z_q=a | e_q=s, z_p=c) = beta / (alpha + beta),
//   alpha = p(z_q=a) p(z_q=!a | e_q=s) p(z_q=!a | z_p=c),
//   beta  = p(z_q=!a) p(z_q=a | e_q=s) p(z_q=a | z_p=c).
// The existence prior p(e_q) is the one consistent with the word's training marginal under the
// detector model: p(z_q) = PzGe p(e_q) + PzGNe (1 - p(e_q)).
//
// The likelihood of all V words is computed FABMAP 2.0 style, and exactly: a place's per-word
// term depends only on whether the place saw the word and on the query bits (z_q, z_parent), so
// only the "active" words (query words and their children) differ from a precomputed all-zero
// query. An inverted index over words visits only places that saw an active word. The dense
// FABMAP 1.0 sum over all words is kept as DenseLogLikelihood, the test oracle.
//
// Localise rules most places out before their last words, exactly. A place's log-likelihood is a
// start value plus one delta per active word it saw; the active words are summed in a fixed order,
// those whose delta is positive first. After the positive ones, every place's partial sum bounds
// its final one from above, and the final sum of the place with the best partial sum (its last
// words added) bounds the best final one from below. A place whose partial sum is below that
// bound cannot be the best, and one more than 41 nats below it (and below the new place) has a
// posterior that Normalise would report as 0 anyway (e^-40 below the best). So only the places
// above both limits get their last words, by a walk over their own words rather than over the
// posting lists, and the others' probabilities are 0. When too many places are left for that to
// pay (near copies of one place, or a flat posterior), the scatter simply goes on. The same test
// is tried once earlier, after half of the positive words, with the sum of the positive deltas
// still to come added to every partial sum as its bound: a revisited place of the synthetic
// benchmark has pulled far enough ahead by then (revisits at 100k places: 0.55-0.61 of the time;
// on real Wi-Fi words, where consecutive scans are near copies, it decides 15 % of UJIIndoorLoc
// queries and no Microsoft ones), and for a new place the test fails after a few hundred places
// (2 % more instructions). Either way every number is the one the exhaustive sum gives, to the
// bit (LocaliseExhaustive is the test oracle). This is FAB-MAP 2.0's bail-out with a bound that
// always holds instead of a probabilistic one.
//
// Normalisation (eq. 3): p(L_i|Z) = p(Z|L_i) p(L_i) / (sum_m p(Z|L_m) p(L_m) + p_new p(Z|L_u)),
// p(L_m) = (1 - p_new) / n_M. The unknown-world likelihood p(Z|L_u) comes from
//   - kSampled: the mean of p(Z|L_u) over unknown-world sample observations (the paper's eq. 3);
//   - kMeanField: one "average place" whose existence probabilities are the samples' marginals.
// The mean-field place is the expectation of the place likelihood over places drawn like the
// samples (exact without the tree, since the likelihood is linear in each p(e_q|L)). A sample
// mean of a heavy-tailed likelihood from a fixed n_s samples is biased low, while the mapped sum
// grows better estimated as the map grows; with kSampled a truly new place is therefore called
// mapped more and more often as places are added. kMeanField stays calibrated (tested at 10k).
#ifndef RATSLAM_FUSION_FABMAP_FABMAP_H_
#define RATSLAM_FUSION_FABMAP_FABMAP_H_

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "common/schema.h"
#include "common/status.h"
#include "fusion/fabmap/chow_liu.h"

namespace ratslam::fabmap {

struct DetectorModel {
  double p_observed_given_exists = 0.39;  // PzGe (openFABMAP default)
  double p_observed_given_absent = 0.0;   // PzGNe (openFABMAP default)

  bool IsValid(std::string* error) const;
  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("p_observed_given_exists", p_observed_given_exists,
      "detector model PzGe: p(word seen given it exists at the place)",
      schema::Unit("").Above(0).Below(1));
    v("p_observed_given_absent", p_observed_given_absent,
      "detector model PzGNe: p(word seen given it is absent at the place)",
      schema::Unit("").AtLeast(0).Below(1));
  }
};

// Words [first_word, first_word + count) use `detector`.
struct DetectorBlock {
  WordId first_word = 0;
  uint32_t count = 0;
  DetectorModel detector;
};

enum class UnknownWorld { kMeanField, kSampled };
std::string ToString(UnknownWorld unknown_world);
StatusOr<UnknownWorld> UnknownWorldFromString(const std::string& name);

struct FabmapOptions {
  double p_new_place = 0.9;  // prior of the unknown world (eq. 3; 0.9 in Cummins and Newman 2008)
  UnknownWorld unknown_world = UnknownWorld::kMeanField;  // how p(Z|L_u) is estimated
  double sample_pseudo_count = 0.5;  // smoothing of the samples' marginals (mean field)

  bool IsValid(std::string* error) const;
  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("p_new_place", p_new_place, "prior of the unknown world (eq. 3)",
      schema::Unit("").Above(0).Below(1));
    v("unknown_world", unknown_world,
      "p(Z|unknown place): mean_field (stays calibrated) or sampled (the paper's eq. 3)",
      schema::Any());
    v("sample_pseudo_count", sample_pseudo_count,
      "pseudo-count smoothing the unknown-world samples' word marginals",
      schema::Unit("").Positive());
  }
};

struct LocalisationResult {
  int64_t best_place = -1;        // -1: the new (unknown) place is the arg-max (eq. 5)
  double best_probability = 0.0;  // posterior of the arg-max hypothesis
  double new_place_probability = 0.0;
  std::vector<double> place_probability;  // per mapped place (or per candidate, in order)
  // The most probable mapped place (a place id; -1 when there is none) and its posterior, whether
  // or not the new place beats it: what a precision-recall curve thresholds.
  int64_t best_mapped_place = -1;
  double best_mapped_probability = 0.0;
  // log(posterior of the best mapped place / posterior of the new place), computed from the
  // log-likelihoods so that it stays finite where both posteriors saturate (0 and 1): the margin
  // by which the best mapped place beat (> 0) or lost to the new place. -inf with no place.
  double best_mapped_log_odds = -std::numeric_limits<double>::infinity();
  // Places ruled out (probability exactly 0) before their last words were summed: a measure of
  // the work Localise saved, not of the answer (which is the exhaustive one).
  uint32_t places_ruled_out = 0;
  // How many of the query's active words were summed for every place before the others were
  // ruled out (all of them when none were): the same kind of measure.
  uint32_t words_summed_for_every_place = 0;
};

class FabmapModel {
 public:
  // `blocks` must cover words 0..tree.size()-1 in order; `unknown_world_samples` are
  // observations over the same words (at least one).
  static StatusOr<FabmapModel> Create(ChowLiuTree tree, std::vector<DetectorBlock> blocks,
                                      std::vector<Observation> unknown_world_samples,
                                      const FabmapOptions& options);

  uint32_t vocabulary_size() const { return tree_.size(); }
  uint32_t places() const { return static_cast<uint32_t>(mapped_.observations.size()); }
  const Observation& place_observation(uint32_t place) const { return mapped_.observations[place]; }
  const FabmapOptions& options() const { return options_; }

  // Adds a place seen as `observation` (normalised; an out-of-vocabulary word is an error).
  StatusOr<uint32_t> AddPlace(Observation observation);

  // log p(Z | L_i) for every mapped place, via the inverted index. `z` must be normalised.
  void LogLikelihoods(const Observation& z, std::vector<double>* log_likelihood) const;
  // The same for one place, summing every word of the vocabulary (FABMAP 1.0; test oracle).
  double DenseLogLikelihood(const Observation& z, uint32_t place) const;
  // log p(Z | L_u), by the configured unknown-world estimate.
  double UnknownWorldLogLikelihood(const Observation& z) const;

  // The posterior over mapped places and the new place (eq. 3, uniform priors, eq. 5 arg-max).
  LocalisationResult Localise(const Observation& z) const;
  // The same with every place's log-likelihood summed in full (the test oracle of Localise's
  // bound: equal to the bit, but for places_ruled_out).
  LocalisationResult LocaliseExhaustive(const Observation& z) const;
  // The same over a subset of places (normalised over them plus the new place); the result's
  // place_probability follows `candidates`' order, best_place is a place id.
  LocalisationResult LocaliseAmong(const Observation& z,
                                   const std::vector<uint32_t>& candidates) const;

 private:
  // Per word, indexed [z_q][z_parent].
  using Table = std::array<std::array<double, 2>, 2>;
  // Places are indexed in blocks of 2^16: a posting is a 16-bit place number within its block,
  // which halves the index and the memory a query streams through (measured: 8-15 % off a
  // query at 100k places).
  static constexpr uint32_t kBlockBits = 16;
  struct PlaceIndex {
    std::vector<Observation> observations;
    // [block][word] -> places of the block that saw the word (ascending, minus the block's first).
    std::vector<std::vector<std::vector<uint16_t>>> postings;
    std::vector<uint32_t> word_places;  // word -> number of places that saw it
    std::vector<double> seen_offset;    // per place: sum over its words of the all-zero delta
    size_t total_words = 0;             // over all places
  };

  FabmapModel() = default;
  void Index(PlaceIndex* index, Observation observation) const;
  // Query bits of the active words (the query's words and their children) and the change each
  // makes to the log-likelihood of a place that saw it; the words with a positive change come
  // first (`positive` of them), which is the order every sum over them follows.
  struct Active {
    std::vector<WordId> words;
    std::vector<uint8_t> z, z_parent;
    std::vector<double> delta;
    size_t positive = 0;
  };
  Active ActiveWords(const Observation& z) const;
  double UnseenLogLikelihood(const Active& active) const;
  double UnknownLogLikelihood(const Active& active) const;
  // Per place of `index`, the log-likelihood with the active words before `words_end` summed
  // (all of them by default).
  void IndexLogLikelihoods(const PlaceIndex& index, const Active& active, std::vector<double>* out,
                           size_t words_end = std::numeric_limits<size_t>::max()) const;
  // Adds active words [begin, end) to every place that saw them.
  static void Scatter(const PlaceIndex& index, const Active& active, size_t begin, size_t end,
                      double* score);
  // Turns per-place log-likelihoods into the posterior, in place: the vector becomes the result's
  // place_probability (no second allocation; only places above the underflow are rescaled).
  LocalisationResult Normalise(std::vector<double> log_likelihood,
                               double unknown_log_likelihood) const;
  // The same when only `candidates` (ascending) can have a non-zero posterior; the others'
  // entries in `log_likelihood` must be 0 already.
  LocalisationResult NormaliseAmong(std::vector<double> log_likelihood,
                                    const std::vector<uint32_t>& candidates,
                                    double unknown_log_likelihood) const;

  ChowLiuTree tree_;
  FabmapOptions options_;
  std::vector<uint32_t> child_begin_;
  std::vector<WordId> children_;
  std::vector<Table> seen_;        // log p(z_q | z_p, place saw q)
  std::vector<Table> unseen_;      // log p(z_q | z_p, place did not see q)
  std::vector<Table> average_;     // log p(z_q | z_p, mean-field unknown place)
  double unseen_all_zero_ = 0.0;   // sum over words of unseen_[q][0][0]
  double average_all_zero_ = 0.0;  // sum over words of average_[q][0][0]
  PlaceIndex mapped_;
  PlaceIndex samples_;
};

}  // namespace ratslam::fabmap

#endif  // RATSLAM_FUSION_FABMAP_FABMAP_H_
