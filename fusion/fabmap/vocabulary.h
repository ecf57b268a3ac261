// Visual words for FABMAP (the fusion paper's section 2.1): features per image, a vocabulary
// trained by clustering descriptors, and bag-of-words quantisation.
//
// Features: FAST corners with ORB binary descriptors (the paper's choice, section 5.1) or SIFT
// (float); both are in Debian's OpenCV. Training is seeded and single-threaded, so a seed gives
// the same vocabulary: k-majority for binary descriptors (Hamming assignment, bitwise-majority
// centres; Grana et al. 2013) and Lloyd's k-means for float ones, both seeded by k-means++; a
// cluster left empty is re-seeded with the descriptor farthest from its centre.
#ifndef RATSLAM_FUSION_FABMAP_VOCABULARY_H_
#define RATSLAM_FUSION_FABMAP_VOCABULARY_H_

#include <cstdint>
#include <string>
#include <vector>

#include "common/gray_image.h"
#include "common/schema.h"
#include "common/status.h"
#include "fusion/fabmap/chow_liu.h"

namespace ratslam::fabmap {

enum class DescriptorKind { kOrb, kSift };
std::string ToString(DescriptorKind kind);
StatusOr<DescriptorKind> DescriptorKindFromString(const std::string& name);

struct FeatureOptions {
  DescriptorKind descriptor = DescriptorKind::kOrb;  // orb (FAST + ORB, binary) or sift (float)
  int max_features = 400;                            // strongest features kept per image
  int fast_threshold = 20;                           // FAST corner threshold (ORB only)

  bool IsValid(std::string* error) const;
  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("descriptor", descriptor, "orb (FAST + ORB, binary) or sift (float)", schema::Any());
    v("max_features", max_features, "strongest features kept per image",
      schema::Unit("features").AtLeast(1));
    v("fast_threshold", fast_threshold, "FAST corner threshold (orb only)",
      schema::Unit("").Within(1, 255));
  }
};

// Descriptors of one or more images, row-major: `count` rows of `length` bytes (ORB) or floats
// (SIFT).
struct DescriptorSet {
  DescriptorKind kind = DescriptorKind::kOrb;
  int length = 0;
  size_t count = 0;
  std::vector<uint8_t> binary;
  std::vector<float> real;

  // Appends `other`'s rows (same kind and length, or this set empty).
  Status Append(const DescriptorSet& other);
};

StatusOr<DescriptorSet> ExtractFeatures(const GrayImage& image, const FeatureOptions& options);

struct VocabularyOptions {
  int words = 1000;                 // vocabulary size
  int iterations = 10;              // clustering iterations
  uint64_t seed = 1;                // picks the initial centres
  size_t max_descriptors = 200000;  // a seeded subsample above this (memory and time)

  bool IsValid(std::string* error) const;
  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("words", words, "visual vocabulary size", schema::Unit("words").AtLeast(1));
    v("iterations", iterations, "clustering iterations", schema::Unit("").AtLeast(1));
    v("seed", seed, "seed of the initial centres", schema::Any());
    v("max_descriptors", max_descriptors, "a seeded subsample of descriptors above this count",
      schema::Unit("descriptors").AtLeast(1));
  }
};

class Vocabulary {
 public:
  Vocabulary() = default;
  uint32_t size() const { return words_; }
  DescriptorKind kind() const { return centres_.kind; }
  // The words of an image: the nearest centre of each descriptor, sorted, no repeats.
  Observation Quantise(const DescriptorSet& descriptors) const;
  std::string Encode() const;
  // `source` names the bytes in messages (a file name).
  static StatusOr<Vocabulary> Decode(const std::string& bytes, const std::string& source);
  static StatusOr<Vocabulary> Train(const DescriptorSet& descriptors,
                                    const VocabularyOptions& options);

 private:
  uint32_t Nearest(const DescriptorSet& set, size_t row) const;
  uint32_t words_ = 0;
  DescriptorSet centres_;
};

}  // namespace ratslam::fabmap

#endif  // RATSLAM_FUSION_FABMAP_VOCABULARY_H_
