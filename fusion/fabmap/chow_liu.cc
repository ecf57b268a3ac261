#include "fusion/fabmap/chow_liu.h"

#include <algorithm>
#include <cmath>

namespace ratslam::fabmap {

bool ChowLiuOptions::IsValid(std::string* error) const {
  if (!(pseudo_count > 0.0) || !std::isfinite(pseudo_count)) {
    if (error) *error = "pseudo_count: must be positive and finite";
    return false;
  }
  return true;
}

void ChowLiuTree::ChildLists(std::vector<uint32_t>* child_begin,
                             std::vector<WordId>* children) const {
  const uint32_t n = size();
  child_begin->assign(n + 1, 0);
  for (WordId q = 0; q < n; ++q) {
    if (parent[q] != kNoParent) ++(*child_begin)[parent[q] + 1];
  }
  for (uint32_t q = 0; q < n; ++q) (*child_begin)[q + 1] += (*child_begin)[q];
  children->assign((*child_begin)[n], 0);
  std::vector<uint32_t> fill(child_begin->begin(), child_begin->end() - 1);
  for (WordId q = 0; q < n; ++q) {
    if (parent[q] != kNoParent) (*children)[fill[parent[q]]++] = q;
  }
}

Status NormaliseObservation(Observation* observation, uint32_t vocabulary_size,
                            const std::string& which) {
  std::sort(observation->begin(), observation->end());
  observation->erase(std::unique(observation->begin(), observation->end()), observation->end());
  if (!observation->empty() && observation->back() >= vocabulary_size) {
    return Status::Error(which + ": word " + std::to_string(observation->back()) +
                         " is outside the vocabulary of " + std::to_string(vocabulary_size) +
                         " words");
  }
  return Status::Ok();
}

namespace {

// p log(p / q) with 0 log 0 = 0.
double Term(double p, double q) { return p > 0.0 ? p * std::log(p / q) : 0.0; }

}  // namespace

double MutualInformation(double n, double n_a, double n_b, double n_ab) {
  if (n <= 0.0) return 0.0;
  const double p_a = n_a / n, p_b = n_b / n;
  const double p11 = n_ab / n;
  const double p10 = (n_a - n_ab) / n;
  const double p01 = (n_b - n_ab) / n;
  const double p00 = (n - n_a - n_b + n_ab) / n;
  const double mi = Term(p11, p_a * p_b) + Term(p10, p_a * (1.0 - p_b)) +
                    Term(p01, (1.0 - p_a) * p_b) + Term(p00, (1.0 - p_a) * (1.0 - p_b));
  return std::max(mi, 0.0);  // rounding can leave -1e-17 for independent words
}

StatusOr<ChowLiuTree> LearnChowLiuTree(const std::vector<Observation>& observations,
                                       uint32_t vocabulary_size, const ChowLiuOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) return Status::Error("Chow-Liu options: " + error);
  if (vocabulary_size == 0) return Status::Error("Chow-Liu tree: the vocabulary is empty");
  if (observations.empty()) return Status::Error("Chow-Liu tree: no training observations");

  // Which observations hold each word (CSR), checking the input as we go.
  std::vector<uint32_t> count(vocabulary_size, 0);
  for (size_t i = 0; i < observations.size(); ++i) {
    const Observation& o = observations[i];
    for (size_t k = 0; k < o.size(); ++k) {
      if (o[k] >= vocabulary_size || (k > 0 && o[k] <= o[k - 1])) {
        return Status::Error("Chow-Liu tree: training observation " + std::to_string(i) +
                             " is not a sorted set of words below " +
                             std::to_string(vocabulary_size));
      }
      ++count[o[k]];
    }
  }
  std::vector<uint32_t> begin(vocabulary_size + 1, 0);
  for (uint32_t q = 0; q < vocabulary_size; ++q) begin[q + 1] = begin[q] + count[q];
  std::vector<uint32_t> holders(begin.back());
  {
    std::vector<uint32_t> fill(begin.begin(), begin.end() - 1);
    for (uint32_t i = 0; i < observations.size(); ++i) {
      for (WordId q : observations[i]) holders[fill[q]++] = i;
    }
  }

  const double n = static_cast<double>(observations.size());
  // log p(z = 0) per word, for the closed form of pairs that never co-occur.
  std::vector<double> log_off(vocabulary_size), p_on(vocabulary_size);
  std::vector<char> constant(vocabulary_size);
  for (uint32_t q = 0; q < vocabulary_size; ++q) {
    p_on[q] = count[q] / n;
    constant[q] = count[q] == 0 || count[q] == observations.size();
    log_off[q] = constant[q] ? 0.0 : std::log1p(-p_on[q]);
  }
  auto mi_never_together = [&](WordId a, WordId b) {
    if (constant[a] || constant[b]) return 0.0;
    const double p00 = 1.0 - p_on[a] - p_on[b];
    const double both_off = p00 > 0.0 ? p00 * (std::log(p00) - log_off[a] - log_off[b]) : 0.0;
    return std::max(0.0, -p_on[a] * log_off[b] - p_on[b] * log_off[a] + both_off);
  };

  // Prim's algorithm for the maximum spanning tree, rooted at word 0; ties go to the lower id.
  ChowLiuTree tree;
  tree.parent.assign(vocabulary_size, ChowLiuTree::kNoParent);
  std::vector<double> key(vocabulary_size, -1.0);
  std::vector<WordId> remaining(vocabulary_size);
  for (uint32_t q = 0; q < vocabulary_size; ++q) remaining[q] = q;
  std::vector<uint32_t> together(vocabulary_size, 0);
  std::vector<WordId> touched;
  WordId u = 0;
  remaining[0] = remaining.back();
  remaining.pop_back();
  while (true) {
    // Co-occurrence counts of u with every word, from u's observations.
    touched.clear();
    for (uint32_t h = begin[u]; h < begin[u + 1]; ++h) {
      for (WordId w : observations[holders[h]]) {
        if (together[w]++ == 0) touched.push_back(w);
      }
    }
    for (WordId v : remaining) {
      const double mi = together[v] != 0 ? MutualInformation(n, count[u], count[v], together[v])
                                         : mi_never_together(u, v);
      if (mi > key[v]) {
        key[v] = mi;
        tree.parent[v] = u;
      }
    }
    for (WordId w : touched) together[w] = 0;
    if (remaining.empty()) break;
    size_t best = 0;
    for (size_t i = 1; i < remaining.size(); ++i) {
      const WordId a = remaining[i], b = remaining[best];
      if (key[a] > key[b] || (key[a] == key[b] && a < b)) best = i;
    }
    u = remaining[best];
    remaining[best] = remaining.back();
    remaining.pop_back();
  }

  // Conditionals from the counts of each word together with its parent.
  std::vector<uint32_t> with_parent(vocabulary_size, 0);
  for (const Observation& o : observations) {
    for (WordId q : o) {
      const WordId p = tree.parent[q];
      if (p != ChowLiuTree::kNoParent && std::binary_search(o.begin(), o.end(), p)) {
        ++with_parent[q];
      }
    }
  }
  const double c = options.pseudo_count;
  tree.marginal.resize(vocabulary_size);
  tree.on_given_parent_on.resize(vocabulary_size);
  tree.on_given_parent_off.resize(vocabulary_size);
  for (uint32_t q = 0; q < vocabulary_size; ++q) {
    tree.marginal[q] = (count[q] + c) / (n + 2.0 * c);
    const WordId p = tree.parent[q];
    if (p == ChowLiuTree::kNoParent) {
      tree.on_given_parent_on[q] = tree.on_given_parent_off[q] = tree.marginal[q];
    } else {
      tree.on_given_parent_on[q] = (with_parent[q] + c) / (count[p] + 2.0 * c);
      tree.on_given_parent_off[q] = (count[q] - with_parent[q] + c) / (n - count[p] + 2.0 * c);
    }
  }
  return tree;
}

ChowLiuTree JoinForest(const ChowLiuTree& first, const ChowLiuTree& second) {
  ChowLiuTree joined = first;
  const WordId offset = first.size();
  for (WordId q = 0; q < second.size(); ++q) {
    const WordId p = second.parent[q];
    joined.parent.push_back(p == ChowLiuTree::kNoParent ? p : p + offset);
  }
  auto append = [](std::vector<double>* to, const std::vector<double>& from) {
    to->insert(to->end(), from.begin(), from.end());
  };
  append(&joined.marginal, second.marginal);
  append(&joined.on_given_parent_on, second.on_given_parent_on);
  append(&joined.on_given_parent_off, second.on_given_parent_off);
  return joined;
}

}  // namespace ratslam::fabmap
