#include "fusion/fabmap/fabmap.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <utility>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace ratslam::fabmap {

bool DetectorModel::IsValid(std::string* error) const {
  if (!schema::CheckFields(*this, error)) return false;
  if (!(p_observed_given_absent < p_observed_given_exists)) {
    if (error) *error = "p_observed_given_absent: must be below p_observed_given_exists";
    return false;
  }
  return true;
}

std::string ToString(UnknownWorld unknown_world) {
  return unknown_world == UnknownWorld::kSampled ? "sampled" : "mean_field";
}

StatusOr<UnknownWorld> UnknownWorldFromString(const std::string& name) {
  if (name == "mean_field") return UnknownWorld::kMeanField;
  if (name == "sampled") return UnknownWorld::kSampled;
  return Status::Error("unknown unknown-world estimate '" + name +
                       "' (expected mean_field or sampled)");
}

bool FabmapOptions::IsValid(std::string* error) const { return schema::CheckFields(*this, error); }

namespace {

constexpr double kMinExistence = 1e-6;

// p(e_q = 1) consistent with the marginal p(z_q = 1) under the detector model.
double ExistencePrior(double marginal, const DetectorModel& d) {
  const double e = (marginal - d.p_observed_given_absent) /
                   (d.p_observed_given_exists - d.p_observed_given_absent);
  return std::clamp(e, kMinExistence, 1.0 - kMinExistence);
}

// p(e = 1 | z) for one observation of the word.
double ExistencePosterior(bool observed, double prior, const DetectorModel& d) {
  const double on = observed ? d.p_observed_given_exists : 1.0 - d.p_observed_given_exists;
  const double off = observed ? d.p_observed_given_absent : 1.0 - d.p_observed_given_absent;
  return on * prior / (on * prior + off * (1.0 - prior));
}

// p(z_q = a | e_q = s, z_p = c) of Cummins and Newman (2008), for word probabilities `marginal`
// (p(z_q=1)) and `given_parent` (p(z_q=1 | z_p=c)).
double ObservationGivenExistence(bool a, bool s, double marginal, double given_parent,
                                 const DetectorModel& d) {
  const double p_on_given_e = s ? d.p_observed_given_exists : d.p_observed_given_absent;
  const double p_a = a ? marginal : 1.0 - marginal;
  const double p_a_given_e = a ? p_on_given_e : 1.0 - p_on_given_e;
  const double p_a_given_parent = a ? given_parent : 1.0 - given_parent;
  const double alpha = p_a * (1.0 - p_a_given_e) * (1.0 - p_a_given_parent);
  const double beta = (1.0 - p_a) * p_a_given_e * p_a_given_parent;
  return alpha + beta > 0.0 ? beta / (alpha + beta) : 0.0;
}

double LogMeanExp(const std::vector<double>& values) {
  if (values.empty()) return -std::numeric_limits<double>::infinity();
  const double top = *std::max_element(values.begin(), values.end());
  double sum = 0.0;
  for (double v : values) sum += std::exp(v - top);
  return top + std::log(sum / static_cast<double>(values.size()));
}

}  // namespace

StatusOr<FabmapModel> FabmapModel::Create(ChowLiuTree tree, std::vector<DetectorBlock> blocks,
                                          std::vector<Observation> unknown_world_samples,
                                          const FabmapOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) return Status::Error("FABMAP options: " + error);
  const uint32_t v = tree.size();
  if (v == 0) return Status::Error("FABMAP: the vocabulary is empty");
  if (tree.marginal.size() != v || tree.on_given_parent_on.size() != v ||
      tree.on_given_parent_off.size() != v) {
    return Status::Error("FABMAP: the Chow-Liu tree's tables do not match its size");
  }
  std::vector<const DetectorModel*> detector(v, nullptr);
  WordId next = 0;
  for (const DetectorBlock& b : blocks) {
    if (!b.detector.IsValid(&error)) return Status::Error("FABMAP detector model: " + error);
    if (b.first_word != next || b.count > v - next) {
      return Status::Error("FABMAP: detector blocks must cover the vocabulary in order");
    }
    for (uint32_t k = 0; k < b.count; ++k) detector[next + k] = &b.detector;
    next += b.count;
  }
  if (next != v) return Status::Error("FABMAP: detector blocks do not cover every word");
  if (unknown_world_samples.empty()) {
    return Status::Error("FABMAP: the unknown world needs at least one sample observation");
  }
  for (size_t i = 0; i < unknown_world_samples.size(); ++i) {
    RATSLAM_RETURN_IF_ERROR(NormaliseObservation(&unknown_world_samples[i], v,
                                                 "unknown-world sample " + std::to_string(i)));
  }

  FabmapModel model;
  model.options_ = options;
  model.tree_ = std::move(tree);
  model.tree_.ChildLists(&model.child_begin_, &model.children_);
  std::vector<uint32_t> sample_count(v, 0);
  for (const Observation& o : unknown_world_samples) {
    for (WordId q : o) ++sample_count[q];
  }
  const double n_s = static_cast<double>(unknown_world_samples.size());
  model.seen_.resize(v);
  model.unseen_.resize(v);
  model.average_.resize(v);
  for (WordId q = 0; q < v; ++q) {
    const DetectorModel& d = *detector[q];
    const ChowLiuTree& t = model.tree_;
    const double prior = ExistencePrior(t.marginal[q], d);
    const double sample_marginal =
        (sample_count[q] + options.sample_pseudo_count) / (n_s + 2.0 * options.sample_pseudo_count);
    const double existence[3] = {ExistencePosterior(true, prior, d),
                                 ExistencePosterior(false, prior, d),
                                 ExistencePrior(sample_marginal, d)};
    Table* tables[3] = {&model.seen_[q], &model.unseen_[q], &model.average_[q]};
    for (int zq = 0; zq < 2; ++zq) {
      for (int zp = 0; zp < 2; ++zp) {
        const double given_parent = zp ? t.on_given_parent_on[q] : t.on_given_parent_off[q];
        const double if_exists =
            ObservationGivenExistence(zq, true, t.marginal[q], given_parent, d);
        const double if_absent =
            ObservationGivenExistence(zq, false, t.marginal[q], given_parent, d);
        for (int k = 0; k < 3; ++k) {
          (*tables[k])[zq][zp] =
              std::log(if_exists * existence[k] + if_absent * (1.0 - existence[k]));
        }
      }
    }
    model.unseen_all_zero_ += model.unseen_[q][0][0];
    model.average_all_zero_ += model.average_[q][0][0];
  }
  model.mapped_.word_places.resize(v);
  model.samples_.word_places.resize(v);
  if (options.unknown_world == UnknownWorld::kSampled) {
    for (Observation& o : unknown_world_samples) model.Index(&model.samples_, std::move(o));
  }
  return model;
}

void FabmapModel::Index(PlaceIndex* index, Observation observation) const {
  const uint32_t place = static_cast<uint32_t>(index->observations.size());
  if ((place >> kBlockBits) == index->postings.size()) {
    index->postings.emplace_back(vocabulary_size());
  }
  std::vector<std::vector<uint16_t>>& block = index->postings.back();
  double offset = 0.0;
  for (WordId q : observation) {
    block[q].push_back(static_cast<uint16_t>(place));
    ++index->word_places[q];
    offset += seen_[q][0][0] - unseen_[q][0][0];
  }
  index->total_words += observation.size();
  index->seen_offset.push_back(offset);
  index->observations.push_back(std::move(observation));
}

StatusOr<uint32_t> FabmapModel::AddPlace(Observation observation) {
  RATSLAM_RETURN_IF_ERROR(NormaliseObservation(&observation, vocabulary_size(), "FABMAP place"));
  Index(&mapped_, std::move(observation));
  return places() - 1;
}

FabmapModel::Active FabmapModel::ActiveWords(const Observation& z) const {
  // Bit sets over the vocabulary (V/8 bytes): the query's words, and words already active.
  const size_t blocks = (vocabulary_size() + 63) / 64;
  std::vector<uint64_t> in_query(blocks, 0), seen(blocks, 0);
  auto test = [](const std::vector<uint64_t>& bits, WordId q) {
    return (bits[q >> 6] >> (q & 63)) & 1;
  };
  auto set = [](std::vector<uint64_t>& bits, WordId q) { bits[q >> 6] |= uint64_t{1} << (q & 63); };
  for (WordId q : z) set(in_query, q);
  struct Word {
    WordId q;
    uint8_t z, z_parent;
    double delta;
  };
  std::vector<Word> found;
  found.reserve(z.size() * 2);
  auto add = [&](WordId q) {
    if (test(seen, q)) return;
    set(seen, q);
    const WordId p = tree_.parent[q];
    const int zq = static_cast<int>(test(in_query, q));
    const int zp = static_cast<int>(p != ChowLiuTree::kNoParent && test(in_query, p));
    const double delta =
        (seen_[q][zq][zp] - unseen_[q][zq][zp]) - (seen_[q][0][0] - unseen_[q][0][0]);
    found.push_back({q, static_cast<uint8_t>(zq), static_cast<uint8_t>(zp), delta});
  };
  for (WordId q : z) {
    add(q);
    for (uint32_t c = child_begin_[q]; c < child_begin_[q + 1]; ++c) add(children_[c]);
  }
  // A stable partition, without branches: positive deltas first, each group in found's order.
  const size_t k = found.size();
  Active active;
  active.words.resize(k);
  active.z.resize(k);
  active.z_parent.resize(k);
  active.delta.resize(k);
  for (const Word& w : found) active.positive += w.delta > 0.0;
  size_t next_positive = 0, next_other = active.positive;
  for (const Word& w : found) {
    const bool positive = w.delta > 0.0;
    const size_t i = positive ? next_positive : next_other;
    next_positive += positive;
    next_other += !positive;
    active.words[i] = w.q;
    active.z[i] = w.z;
    active.z_parent[i] = w.z_parent;
    active.delta[i] = w.delta;
  }
  return active;
}

double FabmapModel::UnseenLogLikelihood(const Active& active) const {
  double sum = unseen_all_zero_;
  for (size_t i = 0; i < active.words.size(); ++i) {
    const Table& t = unseen_[active.words[i]];
    sum += t[active.z[i]][active.z_parent[i]] - t[0][0];
  }
  return sum;
}

void FabmapModel::Scatter(const PlaceIndex& index, const Active& active, size_t begin, size_t end,
                          double* score) {
  // The scores of a block's places (2^16 doubles: 512 KB) outgrow a core's cache, and a posting
  // adds to a score at random: the block is walked in stripes of 2^13 places whose
  // scores stay near the core, every word's list read on from where the last stripe
  // left it. The lists lie far apart in memory: each is fetched a few cache lines ahead of its
  // reading. Prefetch addresses are computed as integers: they may lie past a list's end
  // (harmless for a prefetch, undefined as pointer arithmetic). Each place's words are still
  // added in the active order, so every sum is the same to the bit.
  constexpr size_t kLine = 64 / sizeof(uint16_t), kAhead = 2 * kLine;
  // 64 KB of scores (measured at 100k places: 12 and 14 are slower); a map whose scores fit a
  // core's second-level cache (256 KB) is walked in one stripe, word by word.
  const uint32_t stripe_bits = index.observations.size() <= (size_t{1} << 15) ? kBlockBits : 13;
  auto prefetch = [](const uint16_t* base, size_t offset) {
    __builtin_prefetch(reinterpret_cast<const void*>(reinterpret_cast<uintptr_t>(base) +
                                                     offset * sizeof(uint16_t)));
  };
  const size_t blocks = index.postings.size();
  const size_t words = end > begin ? end - begin : 0;
  std::vector<uint32_t> cursor(words);
  for (size_t b = 0; b < blocks; ++b) {
    const std::vector<std::vector<uint16_t>>& lists = index.postings[b];
    double* block_score = score + (b << kBlockBits);
    std::fill(cursor.begin(), cursor.end(), 0);
    for (size_t i = 0; i < words; ++i) prefetch(lists[active.words[begin + i]].data(), 0);
    // Stripes up to the block's last place (a small map's block is mostly empty).
    const size_t block_places =
        std::min(index.observations.size() - (b << kBlockBits), size_t{1} << kBlockBits);
    for (uint32_t stripe_end = 1u << stripe_bits; stripe_end - (1u << stripe_bits) < block_places;
         stripe_end += 1u << stripe_bits) {
      for (size_t i = 0; i < words; ++i) {
        const std::vector<uint16_t>& places = lists[active.words[begin + i]];
        const uint16_t* place = places.data();
        const size_t m = places.size();
        size_t k = cursor[i];
        if (k == m) continue;
        prefetch(place, k + kAhead);
        const double delta = active.delta[begin + i];
        for (; k < m && place[k] < stripe_end; ++k) block_score[place[k]] += delta;
        cursor[i] = static_cast<uint32_t>(k);
      }
    }
  }
}

void FabmapModel::IndexLogLikelihoods(const PlaceIndex& index, const Active& active,
                                      std::vector<double>* out, size_t words_end) const {
  const double unseen = UnseenLogLikelihood(active);
  const size_t n = index.observations.size();
  out->resize(n);
  double* score = out->data();
  const double* offset = index.seen_offset.data();
  for (size_t i = 0; i < n; ++i) score[i] = unseen + offset[i];
  Scatter(index, active, 0, std::min(words_end, active.words.size()), score);
}

void FabmapModel::LogLikelihoods(const Observation& z, std::vector<double>* log_likelihood) const {
  IndexLogLikelihoods(mapped_, ActiveWords(z), log_likelihood);
}

double FabmapModel::DenseLogLikelihood(const Observation& z, uint32_t place) const {
  const Observation& seen_words = mapped_.observations[place];
  double sum = 0.0;
  for (WordId q = 0; q < vocabulary_size(); ++q) {
    const WordId p = tree_.parent[q];
    const bool zq = std::binary_search(z.begin(), z.end(), q);
    const bool zp = p != ChowLiuTree::kNoParent && std::binary_search(z.begin(), z.end(), p);
    const bool saw = std::binary_search(seen_words.begin(), seen_words.end(), q);
    sum += (saw ? seen_ : unseen_)[q][zq][zp];
  }
  return sum;
}

double FabmapModel::UnknownWorldLogLikelihood(const Observation& z) const {
  return UnknownLogLikelihood(ActiveWords(z));
}

double FabmapModel::UnknownLogLikelihood(const Active& active) const {
  if (options_.unknown_world == UnknownWorld::kSampled) {
    std::vector<double> sample_log_likelihood;
    IndexLogLikelihoods(samples_, active, &sample_log_likelihood);
    return LogMeanExp(sample_log_likelihood);
  }
  double sum = average_all_zero_;
  for (size_t i = 0; i < active.words.size(); ++i) {
    const Table& t = average_[active.words[i]];
    sum += t[active.z[i]][active.z_parent[i]] - t[0][0];
  }
  return sum;
}

namespace {

// A place e^-40 (4e-18) below the best changes no sum in double precision: it costs no exp and
// its probability is reported as 0.
constexpr double kUnderflow = -40.0;
// Localise rules a place out this far beyond the underflow: far more than any rounding of the
// sums here (below 1e-9 nats), so a ruled-out place would have been reported as 0 for certain.
constexpr double kRuleOutMargin = 1.0;

// Appends to `ids` the indices of s[0..n) at or above `threshold`; stops (returning false) when
// a `limit`+1-th would be added.
bool AtOrAbove(const double* s, size_t n, double threshold, size_t limit,
               std::vector<uint32_t>* ids) {
  size_t i = 0;
#if defined(__SSE2__)
  const __m128d t = _mm_set1_pd(threshold);
  for (; i + 4 <= n; i += 4) {
    const __m128d a = _mm_cmpge_pd(_mm_loadu_pd(s + i), t);
    const __m128d b = _mm_cmpge_pd(_mm_loadu_pd(s + i + 2), t);
    if (_mm_movemask_pd(_mm_or_pd(a, b)) == 0) continue;
    for (size_t k = i; k < i + 4; ++k) {
      if (!(s[k] >= threshold)) continue;
      if (ids->size() == limit) return false;
      ids->push_back(static_cast<uint32_t>(k));
    }
  }
#endif
  for (; i < n; ++i) {
    if (!(s[i] >= threshold)) continue;
    if (ids->size() == limit) return false;
    ids->push_back(static_cast<uint32_t>(i));
  }
  return true;
}

// The places of s[0..n) (n > 0) that may still matter: those at or above a threshold that rises
// as the scan goes. `bound(i)` gives a lower bound of the best final sum from place i (its
// completed sum), `threshold_for(lower)` the threshold that lower bound allows. Each new
// largest s[i] (a record; the first is place 0) is completed, so by the end the threshold is at
// least the one the arg max's completed sum gives. Every threshold lies below the record
// (threshold_for(lower) < lower <= s[record]), so a block below the threshold holds no record.
// Usually one pass; when an early, low threshold lets more than 2 `limit` places in, the rest is
// scanned for records only and the places are collected again under the final threshold.
// Returns false when a bound is NaN or more than `limit` places are at or above the final
// threshold. `ids` ascends.
template <typename Bound, typename ThresholdFor>
bool Contenders(const double* s, size_t n, const Bound& bound, const ThresholdFor& threshold_for,
                size_t limit, std::vector<uint32_t>* ids) {
  double record = s[0];
  double lower = bound(0);
  double threshold = threshold_for(lower);
  bool nan = std::isnan(threshold);
  auto new_record = [&](size_t k) {
    record = s[k];
    const double b = bound(k);
    nan = nan || std::isnan(b);
    if (b > lower) {
      lower = b;
      threshold = threshold_for(lower);
    }
  };
  auto below_threshold = [&](uint32_t j) { return !(s[j] >= threshold); };
  size_t i = 0;
  bool collecting = true;
  auto visit = [&](size_t k) {
    if (s[k] > record) new_record(k);
    if (!(s[k] >= threshold)) return;
    ids->push_back(static_cast<uint32_t>(k));
    if (ids->size() <= 2 * limit) return;
    std::erase_if(*ids, below_threshold);
    collecting = ids->size() <= 2 * limit;
  };
#if defined(__SSE2__)
  for (; collecting && !nan && i + 4 <= n; i += 4) {
    const __m128d t = _mm_set1_pd(threshold);
    const __m128d a = _mm_cmpge_pd(_mm_loadu_pd(s + i), t);
    const __m128d b = _mm_cmpge_pd(_mm_loadu_pd(s + i + 2), t);
    if (_mm_movemask_pd(_mm_or_pd(a, b)) == 0) continue;
    for (size_t k = i; k < i + 4; ++k) visit(k);
  }
#endif
  for (; collecting && !nan && i < n; ++i) visit(i);
  if (nan) return false;
  if (collecting) {
    std::erase_if(*ids, below_threshold);
    return ids->size() <= limit;
  }
  // Too many places under an early threshold: the records of the rest, then collect again.
  for (; i < n; ++i) {
    if (s[i] > record) new_record(i);
  }
  if (nan) return false;
  ids->clear();
  return AtOrAbove(s, n, threshold, limit, ids);
}

// Every place id below `n`, as a range (clang 14, which builds the fuzzers, cannot use
// std::views::iota with this libstdc++).
struct AllPlaces {
  struct Iterator {
    size_t i;
    size_t operator*() const { return i; }
    Iterator& operator++() {
      ++i;
      return *this;
    }
    bool operator==(const Iterator&) const = default;
  };
  size_t n;
  Iterator begin() const { return {0}; }
  Iterator end() const { return {n}; }
};

// Normalise over the places `ids` lists (ascending; every other place's probability is 0). With
// `others_zero`, the entries of places not in `ids` are 0 already.
template <typename Ids>
LocalisationResult NormaliseOver(std::vector<double> log_likelihood, const Ids& ids,
                                 bool others_zero, double p_new_place,
                                 double unknown_log_likelihood) {
  LocalisationResult result;
  const size_t n = log_likelihood.size();
  const double log_new = std::log(p_new_place) + unknown_log_likelihood;
  const double log_place_prior =
      n > 0 ? std::log((1.0 - p_new_place) / static_cast<double>(n)) : 0.0;
  double* p = log_likelihood.data();
  const bool any = std::begin(ids) != std::end(ids);
  uint32_t best = any ? static_cast<uint32_t>(*std::begin(ids)) : 0;
  for (const auto i : ids) {
    if (p[i] > p[best]) best = static_cast<uint32_t>(i);
  }
  const double best_log_likelihood = any ? p[best] : 0.0;
  const double top = any ? std::max(log_new, best_log_likelihood + log_place_prior) : log_new;
  const double new_weight = std::exp(log_new - top);
  double total = new_weight;
  // The places above the underflow are few: they alone are rescaled below.
  std::vector<std::pair<uint32_t, double>> kept;  // local: Localise stays thread safe
  for (const auto i : ids) {
    const double relative = p[i] + log_place_prior - top;
    if (relative >= kUnderflow) {
      kept.emplace_back(static_cast<uint32_t>(i), std::exp(relative));
      total += kept.back().second;
    }
  }
  if (others_zero) {
    for (const auto i : ids) p[i] = 0.0;
  } else {
    std::fill(log_likelihood.begin(), log_likelihood.end(), 0.0);
  }
  const double inverse = 1.0 / total;
  for (const auto& [i, weight] : kept) p[i] = weight * inverse;
  result.new_place_probability = new_weight * inverse;
  result.best_probability = result.new_place_probability;
  if (any) {
    result.best_mapped_place = static_cast<int64_t>(best);
    result.best_mapped_probability = p[best];
    result.best_mapped_log_odds = best_log_likelihood + log_place_prior - log_new;
  }
  if (any && p[best] > result.best_probability) {  // a tie goes to the new place
    result.best_probability = p[best];
    result.best_place = static_cast<int64_t>(best);
  }
  result.place_probability = std::move(log_likelihood);
  return result;
}

}  // namespace

LocalisationResult FabmapModel::Normalise(std::vector<double> log_likelihood,
                                          double unknown_log_likelihood) const {
  const AllPlaces all{log_likelihood.size()};
  return NormaliseOver(std::move(log_likelihood), all, false, options_.p_new_place,
                       unknown_log_likelihood);
}

LocalisationResult FabmapModel::NormaliseAmong(std::vector<double> log_likelihood,
                                               const std::vector<uint32_t>& candidates,
                                               double unknown_log_likelihood) const {
  return NormaliseOver(std::move(log_likelihood), candidates, true, options_.p_new_place,
                       unknown_log_likelihood);
}

LocalisationResult FabmapModel::LocaliseExhaustive(const Observation& z) const {
  const Active active = ActiveWords(z);
  std::vector<double> log_likelihood;
  IndexLogLikelihoods(mapped_, active, &log_likelihood);
  const double unknown = UnknownLogLikelihood(active);
  LocalisationResult result = Normalise(std::move(log_likelihood), unknown);
  result.words_summed_for_every_place = static_cast<uint32_t>(active.words.size());
  return result;
}

LocalisationResult FabmapModel::Localise(const Observation& z) const {
  // See the header: the first positive words for every place, and when one place already leads
  // by more than the rest of them can make up, the remaining words only for the places that can
  // still be the best or have a posterior above the underflow; otherwise the same after all the
  // positive words; otherwise every word for every place.
  const Active active = ActiveWords(z);
  const double unknown = UnknownLogLikelihood(active);
  const size_t n = mapped_.observations.size();
  const size_t m = active.words.size();
  const size_t positive = active.positive;
  // The early check comes after half of the positive words: a revisit's place leads by then
  // (measured on synthetic worlds: after a quarter it almost never does), and a new place's
  // check fails within a few postings (below).
  const size_t early = positive >= 16 ? positive / 2 : positive;
  std::vector<double> log_likelihood;
  IndexLogLikelihoods(mapped_, active, &log_likelihood, early);
  double* score = log_likelihood.data();
  size_t scattered = early;  // words [0, scattered) are in every place's score
  auto scatter_the_rest = [&] {
    Scatter(mapped_, active, scattered, m, score);
    LocalisationResult result = Normalise(std::move(log_likelihood), unknown);
    result.words_summed_for_every_place = static_cast<uint32_t>(m);
    return result;
  };
  if (n == 0) return scatter_the_rest();
  // Completing a place walks its own words and the active ones not yet summed; that must cost
  // well under the postings it saves.
  auto max_candidates = [&](size_t from) {
    size_t remaining_postings = 0;
    for (size_t i = from; i < m; ++i) remaining_postings += mapped_.word_places[active.words[i]];
    const double walk = static_cast<double>(m - from) +
                        static_cast<double>(mapped_.total_words) / static_cast<double>(n) + 1.0;
    return static_cast<size_t>(0.5 * static_cast<double>(remaining_postings) / walk);
  };
  // Bit set of one place's words, cleared after each use.
  std::vector<uint64_t> bits((vocabulary_size() + 63) / 64, 0);
  // A place's final sum from its score with words [0, scattered) in it: the same additions, in
  // the same order, as the scatter would make.
  auto complete = [&](uint32_t place) {
    const Observation& words = mapped_.observations[place];
    for (WordId q : words) bits[q >> 6] |= uint64_t{1} << (q & 63);
    double sum = score[place];
    for (size_t i = scattered; i < m; ++i) {
      const WordId q = active.words[i];
      if ((bits[q >> 6] >> (q & 63)) & 1) sum += active.delta[i];
    }
    for (WordId q : words) bits[q >> 6] = 0;
    return sum;
  };
  // Any place's final sum is a lower bound of the best final sum; a place whose final sum is
  // below threshold_for(that bound) can be neither the best nor within the underflow of it or of
  // the new place.
  const double log_place_prior = std::log((1.0 - options_.p_new_place) / static_cast<double>(n));
  const double new_place = std::log(options_.p_new_place) + unknown - log_place_prior;
  auto threshold_for = [&](double best_lower) {
    return std::min(best_lower, std::max(best_lower, new_place) + kUnderflow - kRuleOutMargin) -
           kRuleOutMargin;
  };
  // Only `candidates` (ascending) can matter: complete them and normalise over them.
  auto finish_among = [&](const std::vector<uint32_t>& candidates) {
    std::vector<double> final_sum(candidates.size());
    for (size_t k = 0; k < candidates.size(); ++k) final_sum[k] = complete(candidates[k]);
    std::fill(log_likelihood.begin(), log_likelihood.end(), 0.0);
    for (size_t k = 0; k < candidates.size(); ++k) score[candidates[k]] = final_sum[k];
    LocalisationResult result = NormaliseAmong(std::move(log_likelihood), candidates, unknown);
    result.places_ruled_out = static_cast<uint32_t>(n - candidates.size());
    result.words_summed_for_every_place = static_cast<uint32_t>(scattered);
    return result;
  };
  std::vector<uint32_t> candidates;
  if (early < positive) {
    // The positive words still to come can raise a place by at most their sum, the others only
    // lower it: a place more than that below the threshold now is out. The lower bound is the
    // final sum of the place leading among those that saw one of the last four words summed (a
    // place seen again has most of the query's words, so it is likely in one of those lists; any
    // place gives a valid bound). A new place leaves the threshold far below most places, and
    // the collection stops at the first max_candidates + 1.
    uint32_t lead = 0;
    bool any = false;
    double still_to_come = 0.0;
    for (size_t i = scattered; i < positive; ++i) still_to_come += active.delta[i];
    for (size_t i = scattered >= 4 ? scattered - 4 : 0; i < scattered; ++i) {
      const WordId q = active.words[i];
      for (size_t b = 0; b < mapped_.postings.size(); ++b) {
        const uint32_t first = static_cast<uint32_t>(b << kBlockBits);
        for (uint16_t place : mapped_.postings[b][q]) {
          if (!any || score[first + place] > score[lead]) lead = first + place;
          any = true;
        }
      }
    }
    const double threshold = any ? threshold_for(complete(lead)) - still_to_come : 0.0;
    if (any && std::isfinite(threshold) &&
        AtOrAbove(score, n, threshold, max_candidates(scattered), &candidates)) {
      return finish_among(candidates);
    }
    candidates.clear();
  }
  Scatter(mapped_, active, scattered, positive, score);
  scattered = positive;
  // After the positive words every remaining delta is <= 0, so a partial sum is an upper bound
  // of the place's final sum.
  const size_t limit = max_candidates(positive);
  if (limit == 0) return scatter_the_rest();
  auto bound = [&](size_t place) { return complete(static_cast<uint32_t>(place)); };
  if (!Contenders(score, n, bound, threshold_for, limit, &candidates)) return scatter_the_rest();
  return finish_among(candidates);
}

LocalisationResult FabmapModel::LocaliseAmong(const Observation& z,
                                              const std::vector<uint32_t>& candidates) const {
  const Active active = ActiveWords(z);
  std::vector<double> all;
  IndexLogLikelihoods(mapped_, active, &all);
  std::vector<double> subset;
  subset.reserve(candidates.size());
  for (uint32_t c : candidates) subset.push_back(all.at(c));
  LocalisationResult result = Normalise(std::move(subset), UnknownLogLikelihood(active));
  if (result.best_place >= 0) result.best_place = candidates[result.best_place];
  if (result.best_mapped_place >= 0) {
    result.best_mapped_place = candidates[result.best_mapped_place];
  }
  return result;
}

}  // namespace ratslam::fabmap
