#include "fusion/fabmap/synthetic_words.h"

#include <algorithm>

namespace ratslam::fabmap {

Observation SyntheticWordWorld::SamplePlace(Random* random) const {
  // Even words exist independently with probability p; an odd word follows its even neighbour
  // with p_follow, else exists with p. Per pair: p + p p_follow + (1 - p) p ~ p (2 + p_follow).
  const double existing = mean_words_per_observation / p_detect;
  const double p = std::min(0.5, 2.0 * existing / (vocabulary_size * (2.0 + p_follow)));
  Observation place;
  bool previous = false;
  for (WordId q = 0; q < vocabulary_size; ++q) {
    const bool follows = (q % 2 == 1) && previous;
    const bool exists = follows ? random->Uniform() < p_follow : random->Uniform() < p;
    if (exists) place.push_back(q);
    previous = exists;
  }
  return place;
}

Observation SyntheticWordWorld::Observe(const Observation& place, Random* random) const {
  Observation seen;
  for (WordId q : place) {
    if (random->Uniform() < p_detect) seen.push_back(q);
  }
  return seen;
}

}  // namespace ratslam::fabmap
