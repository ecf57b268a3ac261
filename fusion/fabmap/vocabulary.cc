#include "fusion/fabmap/vocabulary.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

#include "common/byte_buffer.h"
#include "common/random.h"

namespace ratslam::fabmap {

std::string ToString(DescriptorKind kind) { return kind == DescriptorKind::kSift ? "sift" : "orb"; }

StatusOr<DescriptorKind> DescriptorKindFromString(const std::string& name) {
  if (name == "orb") return DescriptorKind::kOrb;
  if (name == "sift") return DescriptorKind::kSift;
  return Status::Error("unknown descriptor '" + name + "' (expected orb or sift)");
}

bool FeatureOptions::IsValid(std::string* error) const { return schema::CheckFields(*this, error); }

bool VocabularyOptions::IsValid(std::string* error) const {
  return schema::CheckFields(*this, error);
}

Status DescriptorSet::Append(const DescriptorSet& other) {
  if (other.count == 0) return Status::Ok();
  if (count == 0) {
    kind = other.kind;
    length = other.length;
  } else if (kind != other.kind || length != other.length) {
    return Status::Error("descriptor sets of different kinds cannot be joined");
  }
  binary.insert(binary.end(), other.binary.begin(), other.binary.end());
  real.insert(real.end(), other.real.begin(), other.real.end());
  count += other.count;
  return Status::Ok();
}

StatusOr<DescriptorSet> ExtractFeatures(const GrayImage& image, const FeatureOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) return Status::Error("feature options: " + error);
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != static_cast<size_t>(image.width) * image.height) {
    return Status::Error("feature extraction: the image is empty or its size is inconsistent");
  }
  const cv::Mat view(image.height, image.width, CV_8UC1, const_cast<uint8_t*>(image.pixels.data()));
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  DescriptorSet set;
  set.kind = options.descriptor;
  if (options.descriptor == DescriptorKind::kOrb) {
    auto orb = cv::ORB::create(options.max_features, 1.2f, 8, 15, 0, 2, cv::ORB::FAST_SCORE, 31,
                               options.fast_threshold);
    orb->detectAndCompute(view, cv::noArray(), keypoints, descriptors);
    set.length = 32;
    if (!descriptors.empty()) {
      set.count = static_cast<size_t>(descriptors.rows);
      set.binary.assign(descriptors.data, descriptors.data + descriptors.total());
    }
  } else {
    auto sift = cv::SIFT::create(options.max_features);
    sift->detectAndCompute(view, cv::noArray(), keypoints, descriptors);
    set.length = 128;
    if (!descriptors.empty()) {
      set.count = static_cast<size_t>(descriptors.rows);
      const float* begin = descriptors.ptr<float>(0);
      set.real.assign(begin, begin + descriptors.total());
    }
  }
  return set;
}

namespace {

int Hamming(const uint8_t* a, const uint8_t* b, int length) {
  int d = 0;
  int i = 0;
  for (; i + 8 <= length; i += 8) {
    uint64_t x, y;
    std::memcpy(&x, a + i, 8);
    std::memcpy(&y, b + i, 8);
    d += std::popcount(x ^ y);
  }
  for (; i < length; ++i) d += std::popcount(static_cast<unsigned>(a[i] ^ b[i]));
  return d;
}

float SquaredDistance(const float* a, const float* b, int length) {
  float d = 0.0f;
  for (int i = 0; i < length; ++i) d += (a[i] - b[i]) * (a[i] - b[i]);
  return d;
}

// Distance of row `r` of `set` to centre `c` of `centres`, as a double.
double Distance(const DescriptorSet& set, size_t r, const DescriptorSet& centres, size_t c) {
  const int n = set.length;
  if (set.kind == DescriptorKind::kOrb) {
    return Hamming(&set.binary[r * n], &centres.binary[c * n], n);
  }
  return SquaredDistance(&set.real[r * n], &centres.real[c * n], n);
}

void CopyRow(const DescriptorSet& from, size_t r, DescriptorSet* to, size_t c) {
  const int n = from.length;
  if (from.kind == DescriptorKind::kOrb) {
    std::copy_n(&from.binary[r * n], n, &to->binary[c * n]);
  } else {
    std::copy_n(&from.real[r * n], n, &to->real[c * n]);
  }
}

// A seeded choice of `k` distinct indices below `n` (partial Fisher-Yates).
std::vector<size_t> DistinctIndices(size_t n, size_t k, Random* random) {
  std::vector<size_t> all(n);
  for (size_t i = 0; i < n; ++i) all[i] = i;
  for (size_t i = 0; i < k; ++i) {
    const size_t j = i + static_cast<size_t>(random->NextU64() % (n - i));
    std::swap(all[i], all[j]);
  }
  all.resize(k);
  return all;
}

}  // namespace

uint32_t Vocabulary::Nearest(const DescriptorSet& set, size_t row) const {
  const int n = set.length;
  uint32_t best = 0;
  if (set.kind == DescriptorKind::kOrb) {
    int best_distance = std::numeric_limits<int>::max();
    const uint8_t* query = &set.binary[row * n];
    for (uint32_t c = 0; c < words_; ++c) {
      const int d = Hamming(query, &centres_.binary[static_cast<size_t>(c) * n], n);
      if (d < best_distance) {
        best_distance = d;
        best = c;
      }
    }
    return best;
  }
  float best_distance = std::numeric_limits<float>::infinity();
  const float* query = &set.real[row * n];
  for (uint32_t c = 0; c < words_; ++c) {
    const float d = SquaredDistance(query, &centres_.real[static_cast<size_t>(c) * n], n);
    if (d < best_distance) {
      best_distance = d;
      best = c;
    }
  }
  return best;
}

Observation Vocabulary::Quantise(const DescriptorSet& descriptors) const {
  Observation words;
  if (words_ == 0 || descriptors.kind != centres_.kind || descriptors.length != centres_.length) {
    return words;
  }
  words.reserve(descriptors.count);
  for (size_t r = 0; r < descriptors.count; ++r) words.push_back(Nearest(descriptors, r));
  std::sort(words.begin(), words.end());
  words.erase(std::unique(words.begin(), words.end()), words.end());
  return words;
}

StatusOr<Vocabulary> Vocabulary::Train(const DescriptorSet& all_descriptors,
                                       const VocabularyOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) return Status::Error("vocabulary options: " + error);
  if (all_descriptors.count < static_cast<size_t>(options.words)) {
    return Status::Error("vocabulary: " + std::to_string(all_descriptors.count) +
                         " descriptors cannot make " + std::to_string(options.words) + " words");
  }
  Random random(options.seed);
  // A seeded subsample bounds time and memory.
  DescriptorSet data;
  if (all_descriptors.count > options.max_descriptors) {
    data.kind = all_descriptors.kind;
    data.length = all_descriptors.length;
    data.count = options.max_descriptors;
    (data.kind == DescriptorKind::kOrb ? data.binary.resize(data.count * data.length)
                                       : data.real.resize(data.count * data.length));
    std::vector<size_t> pick = DistinctIndices(all_descriptors.count, data.count, &random);
    std::sort(pick.begin(), pick.end());
    for (size_t i = 0; i < pick.size(); ++i) CopyRow(all_descriptors, pick[i], &data, i);
  } else {
    data = all_descriptors;
  }

  Vocabulary v;
  v.words_ = static_cast<uint32_t>(options.words);
  v.centres_.kind = data.kind;
  v.centres_.length = data.length;
  v.centres_.count = v.words_;
  const int n = data.length;
  if (data.kind == DescriptorKind::kOrb) {
    v.centres_.binary.resize(static_cast<size_t>(v.words_) * n);
  } else {
    v.centres_.real.resize(static_cast<size_t>(v.words_) * n);
  }
  // k-means++ seeding (Arthur and Vassilvitskii 2007) over a seeded pool of at most 16 k
  // descriptors: each next centre is drawn with probability proportional to its squared
  // distance from the nearest centre so far.
  {
    const size_t pool_size = std::min(data.count, static_cast<size_t>(v.words_) * 16);
    const std::vector<size_t> pool = DistinctIndices(data.count, pool_size, &random);
    std::vector<double> nearest(pool_size, std::numeric_limits<double>::infinity());
    CopyRow(data, pool[0], &v.centres_, 0);
    for (uint32_t c = 1; c < v.words_; ++c) {
      double total = 0.0;
      for (size_t i = 0; i < pool_size; ++i) {
        const double d = Distance(data, pool[i], v.centres_, c - 1);
        nearest[i] = std::min(nearest[i], data.kind == DescriptorKind::kOrb ? d * d : d);
        total += nearest[i];
      }
      size_t chosen = static_cast<size_t>(random.NextU64() % pool_size);
      if (total > 0.0) {
        double target = random.Uniform() * total;
        for (size_t i = 0; i < pool_size; ++i) {
          target -= nearest[i];
          if (target < 0.0 && nearest[i] > 0.0) {
            chosen = i;
            break;
          }
        }
      }
      CopyRow(data, pool[chosen], &v.centres_, c);
    }
  }

  std::vector<uint32_t> assignment(data.count, 0);
  std::vector<double> distance(data.count, 0.0);
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    bool changed = false;
    for (size_t r = 0; r < data.count; ++r) {
      const uint32_t c = v.Nearest(data, r);
      changed |= c != assignment[r] || iteration == 0;
      assignment[r] = c;
      distance[r] = Distance(data, r, v.centres_, c);
    }
    if (!changed) break;
    // New centres: bitwise majority (binary) or the mean (float) of each cluster's members.
    std::vector<uint32_t> members(v.words_, 0);
    std::vector<double> sums(
        static_cast<size_t>(v.words_) * n * (data.kind == DescriptorKind::kOrb ? 8 : 1), 0.0);
    for (size_t r = 0; r < data.count; ++r) {
      const uint32_t c = assignment[r];
      ++members[c];
      if (data.kind == DescriptorKind::kOrb) {
        for (int b = 0; b < n * 8; ++b) {
          sums[static_cast<size_t>(c) * n * 8 + b] += (data.binary[r * n + b / 8] >> (b % 8)) & 1;
        }
      } else {
        for (int k = 0; k < n; ++k) sums[static_cast<size_t>(c) * n + k] += data.real[r * n + k];
      }
    }
    for (uint32_t c = 0; c < v.words_; ++c) {
      if (members[c] == 0) {
        // Re-seed an empty cluster with the worst-fitting descriptor.
        const size_t worst = static_cast<size_t>(
            std::max_element(distance.begin(), distance.end()) - distance.begin());
        CopyRow(data, worst, &v.centres_, c);
        distance[worst] = 0.0;
        continue;
      }
      if (data.kind == DescriptorKind::kOrb) {
        for (int byte = 0; byte < n; ++byte) {
          uint8_t value = 0;
          for (int bit = 0; bit < 8; ++bit) {
            if (2.0 * sums[static_cast<size_t>(c) * n * 8 + byte * 8 + bit] > members[c]) {
              value |= static_cast<uint8_t>(1u << bit);
            }
          }
          v.centres_.binary[static_cast<size_t>(c) * n + byte] = value;
        }
      } else {
        for (int k = 0; k < n; ++k) {
          v.centres_.real[static_cast<size_t>(c) * n + k] =
              static_cast<float>(sums[static_cast<size_t>(c) * n + k] / members[c]);
        }
      }
    }
  }
  return v;
}

namespace {
constexpr uint32_t kVocabularyMagic = 0x424f5652;  // "RVOB"
constexpr uint32_t kVocabularyVersion = 1;
}  // namespace

std::string Vocabulary::Encode() const {
  ByteWriter w;
  w.Pod(kVocabularyMagic);
  w.Pod(kVocabularyVersion);
  w.Pod<uint8_t>(centres_.kind == DescriptorKind::kOrb ? 0 : 1);
  w.Pod<int32_t>(centres_.length);
  w.Pod<uint32_t>(words_);
  w.PodVector(centres_.binary);
  w.PodVector(centres_.real);
  return std::move(w.bytes());
}

StatusOr<Vocabulary> Vocabulary::Decode(const std::string& bytes, const std::string& source) {
  ByteReader r(bytes, source);
  uint32_t magic = 0, version = 0, words = 0;
  uint8_t kind = 0;
  int32_t length = 0;
  Vocabulary v;
  if (!(r.Pod(&magic) && (magic == kVocabularyMagic || r.Fail("not a vocabulary file")) &&
        r.Pod(&version) && (version == kVocabularyVersion || r.Fail("unsupported version")) &&
        r.Pod(&kind) && (kind <= 1 || r.Fail("unknown descriptor kind")) && r.Pod(&length) &&
        r.Pod(&words) && r.PodVector(&v.centres_.binary) && r.PodVector(&v.centres_.real) &&
        (r.AtEnd() || r.Fail("trailing bytes")))) {
    return Status::Error(r.error());
  }
  v.centres_.kind = kind == 0 ? DescriptorKind::kOrb : DescriptorKind::kSift;
  const int expected_length = kind == 0 ? 32 : 128;
  const size_t rows = static_cast<size_t>(words) * expected_length;
  const bool sizes_ok = length == expected_length && words > 0 &&
                        (kind == 0 ? v.centres_.binary.size() == rows && v.centres_.real.empty()
                                   : v.centres_.real.size() == rows && v.centres_.binary.empty());
  if (!sizes_ok) return Status::Error(source + ": the centre table does not match its header");
  for (float x : v.centres_.real) {
    if (!std::isfinite(x)) return Status::Error(source + ": a centre is not finite");
  }
  v.centres_.length = length;
  v.centres_.count = words;
  v.words_ = words;
  return v;
}

}  // namespace ratslam::fabmap
