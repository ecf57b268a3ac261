// Synthetic word worlds for FABMAP tests and benchmarks: places own sets of existing words with a
// planted dependency (odd word q tends to exist with word q-1), and an observation of a place
// sees each existing word with the detector's probability. Seeded and deterministic.
#ifndef RATSLAM_FUSION_FABMAP_SYNTHETIC_WORDS_H_
#define RATSLAM_FUSION_FABMAP_SYNTHETIC_WORDS_H_

#include <cstdint>
#include <vector>

#include "common/random.h"
#include "fusion/fabmap/chow_liu.h"

namespace ratslam::fabmap {

struct SyntheticWordWorld {
  uint32_t vocabulary_size = 1000;
  double mean_words_per_observation = 50.0;  // expected observed words
  double p_detect = 0.8;                     // p(z = 1 | e = 1)
  double p_follow = 0.8;                     // p(e_q = 1 | e_{q-1} = 1) for odd q

  // A place: the words that exist there.
  Observation SamplePlace(Random* random) const;
  // One observation of `place`.
  Observation Observe(const Observation& place, Random* random) const;
};

}  // namespace ratslam::fabmap

#endif  // RATSLAM_FUSION_FABMAP_SYNTHETIC_WORDS_H_
