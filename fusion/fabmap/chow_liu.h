// Chow-Liu trees over binary word observations (Chow and Liu 1968), as FABMAP uses them to model
// which words co-occur (Cummins and Newman 2008; the fusion paper's section 2.2).
//
// Learning is sparse: co-occurrence counts come from each word's list of observations, so the
// cost is O(N L^2) for N observations of L words, plus O(V^2) for Prim's maximum spanning tree on
// the complete graph of V words (mutual information of a pair that never co-occurs is a closed
// form of the two marginals). Memory is O(V + N L).
#ifndef RATSLAM_FUSION_FABMAP_CHOW_LIU_H_
#define RATSLAM_FUSION_FABMAP_CHOW_LIU_H_

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "common/status.h"

namespace ratslam::fabmap {

using WordId = uint32_t;
// The words present in one observation: sorted, no repeats.
using Observation = std::vector<WordId>;

struct ChowLiuOptions {
  double pseudo_count = 0.5;  // added to every cell of the count tables (conditionals, marginals)

  bool IsValid(std::string* error) const;
};

// A forest over words 0..size()-1: each word has a parent or is a root. Probabilities are of the
// word being observed (z = 1).
struct ChowLiuTree {
  static constexpr WordId kNoParent = std::numeric_limits<WordId>::max();

  std::vector<WordId> parent;
  std::vector<double> marginal;             // p(z_q = 1)
  std::vector<double> on_given_parent_on;   // p(z_q = 1 | z_parent = 1); marginal for a root
  std::vector<double> on_given_parent_off;  // p(z_q = 1 | z_parent = 0); marginal for a root

  uint32_t size() const { return static_cast<uint32_t>(parent.size()); }
  // Children of every word, as offsets into `children` (CSR): word q's are
  // children[child_begin[q] .. child_begin[q+1]).
  void ChildLists(std::vector<uint32_t>* child_begin, std::vector<WordId>* children) const;
};

// Sorts and de-duplicates `observation`; fails naming `which` when a word is >= vocabulary_size.
Status NormaliseObservation(Observation* observation, uint32_t vocabulary_size,
                            const std::string& which);

// Learns the maximum-mutual-information tree over `vocabulary_size` words from `observations`
// (each sorted and unique; see NormaliseObservation). Needs at least one observation.
StatusOr<ChowLiuTree> LearnChowLiuTree(const std::vector<Observation>& observations,
                                       uint32_t vocabulary_size,
                                       const ChowLiuOptions& options = {});

// Mutual information (nats) of two binary variables from counts: n observations, n_a and n_b
// with each variable on, n_ab with both on.
double MutualInformation(double n, double n_a, double n_b, double n_ab);

// One forest from two: `second`'s words follow `first`'s (ids offset by first.size()). Used for
// early fusion, where visual and Wi-Fi words have separate trees (the paper's section 4.3).
ChowLiuTree JoinForest(const ChowLiuTree& first, const ChowLiuTree& second);

}  // namespace ratslam::fabmap

#endif  // RATSLAM_FUSION_FABMAP_CHOW_LIU_H_
