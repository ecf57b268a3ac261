#include "sensors/sequence_matcher.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#if defined(__x86_64__)
#include <immintrin.h>
#define RATSLAM_HAVE_X86_SIMD 1
#endif

namespace ratslam::sensors {
namespace {

constexpr int kRowAlignment = 32;  // bytes: one AVX2 register

uint64_t SadPortable(const uint8_t* a, const uint8_t* b, size_t n) {
#if defined(RATSLAM_HAVE_X86_SIMD)
  __m128i acc = _mm_setzero_si128();
  for (size_t i = 0; i < n; i += 16) {
    acc =
        _mm_add_epi64(acc, _mm_sad_epu8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(a + i)),
                                        _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + i))));
  }
  return static_cast<uint64_t>(_mm_cvtsi128_si64(acc)) +
         static_cast<uint64_t>(_mm_cvtsi128_si64(_mm_unpackhi_epi64(acc, acc)));
#else
  uint64_t sum = 0;
  for (size_t i = 0; i < n; ++i) sum += static_cast<uint64_t>(std::abs(int(a[i]) - int(b[i])));
  return sum;
#endif
}

#if defined(RATSLAM_HAVE_X86_SIMD)
__attribute__((target("avx2"))) uint64_t SadAvx2(const uint8_t* a, const uint8_t* b, size_t n) {
  __m256i acc = _mm256_setzero_si256();
  for (size_t i = 0; i < n; i += 32) {
    acc = _mm256_add_epi64(
        acc, _mm256_sad_epu8(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(a + i)),
                             _mm256_loadu_si256(reinterpret_cast<const __m256i*>(b + i))));
  }
  const __m128i sum = _mm_add_epi64(_mm256_castsi256_si128(acc), _mm256_extracti128_si256(acc, 1));
  return static_cast<uint64_t>(_mm_cvtsi128_si64(sum)) +
         static_cast<uint64_t>(_mm_cvtsi128_si64(_mm_unpackhi_epi64(sum, sum)));
}
#endif

using SadKernel = uint64_t (*)(const uint8_t*, const uint8_t*, size_t);

SadKernel ChooseSad() {
#if defined(RATSLAM_HAVE_X86_SIMD)
  if (__builtin_cpu_supports("avx2")) return SadAvx2;
#endif
  return SadPortable;
}

// Both kernels sum the same integers, so the choice never changes a result.
const SadKernel kSad = ChooseSad();

// The best place and how far ahead of the best outside its exclusion window it is.
SequenceMatch MatchOf(const std::vector<double>& score, int candidates, int exclusion) {
  SequenceMatch m;
  m.candidates = PlaceCandidates(score, std::max(candidates, 1), exclusion);
  if (m.candidates.empty()) return m;
  m.declined = false;
  m.reference = m.candidates.front().reference;
  double runner_up = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < score.size(); ++i) {
    if (std::abs(static_cast<int>(i) - m.reference) > exclusion) {
      runner_up = std::min(runner_up, score[i]);
    }
  }
  m.confidence = std::isfinite(runner_up) ? runner_up - m.candidates.front().score : 0.0;
  m.candidates.resize(std::min<size_t>(m.candidates.size(), std::max(candidates, 0)));
  return m;
}

}  // namespace

std::vector<PlaceCandidate> PlaceCandidates(const std::vector<double>& score, int count,
                                            int exclusion) {
  std::vector<PlaceCandidate> out;
  const int n = static_cast<int>(score.size());
  while (static_cast<int>(out.size()) < count) {
    int best = -1;
    for (int i = 0; i < n; ++i) {
      // Strictly smaller: a tie goes to the lower index.
      if (!(score[i] < (best < 0 ? std::numeric_limits<double>::infinity() : score[best]))) {
        continue;
      }
      const bool apart = std::all_of(out.begin(), out.end(), [&](const PlaceCandidate& c) {
        return std::abs(c.reference - i) > exclusion;
      });
      if (apart) best = i;
    }
    if (best < 0) break;
    out.push_back({best, score[best]});
  }
  return out;
}

bool SequenceMatcherOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (patch_px < 1) return fail("patch_px must be at least 1");
  if (sequence_length < 1) return fail("sequence_length must be at least 1");
  if (!(min_velocity >= 0) || !(max_velocity >= min_velocity)) {
    return fail("velocities must satisfy 0 <= min_velocity <= max_velocity");
  }
  if (velocity_steps < 1) return fail("velocity_steps must be at least 1");
  if (contrast_window < 0 || exclusion_window < 0) return fail("windows must not be negative");
  if (!(blank_contrast >= 0)) return fail("blank_contrast must not be negative");
  if (image_width_px < 0 || image_height_px < 0) return fail("image sizes must not be negative");
  if ((image_width_px == 0) != (image_height_px == 0)) {
    return fail("image_width_px and image_height_px are both set or both 0");
  }
  if (centred && recognise_views) {
    return fail("centred needs the frames after a query: evaluate only, not recognise_views");
  }
  if (!(min_confidence >= 0)) return fail("min_confidence must not be negative");
  if (recency_frames < 0 || min_references < 0) {
    return fail("recency_frames and min_references must not be negative");
  }
  return true;
}

PreparedFrame PrepareFrame(const uint8_t* pixels, int width, int height, int patch_px,
                           double blank_contrast) {
  PreparedFrame f;
  f.width = width;
  f.height = height;
  const int stride = (width + kRowAlignment - 1) / kRowAlignment * kRowAlignment;
  f.bytes.assign(static_cast<size_t>(stride) * height, 128);
  const size_t n = static_cast<size_t>(width) * height;
  if (n == 0) {
    f.blank = true;
    return f;
  }
  // Blank: the grey levels between the 5th and 95th percentiles span less than blank_contrast.
  // Percentiles, not the standard deviation: a black frame with a few bright pixels (a logo, a
  // lamp) has a standard deviation of several levels and nothing to match.
  size_t histogram[256] = {};
  for (size_t i = 0; i < n; ++i) ++histogram[pixels[i]];
  auto percentile = [&](double fraction) {
    const size_t rank = static_cast<size_t>(fraction * static_cast<double>(n - 1));
    size_t seen = 0;
    for (int v = 0; v < 256; ++v) {
      seen += histogram[v];
      if (seen > rank) return v;
    }
    return 255;
  };
  f.blank = percentile(0.95) - percentile(0.05) < blank_contrast;
  const int p = std::max(1, patch_px);
  for (int y0 = 0; y0 < height; y0 += p) {
    for (int x0 = 0; x0 < width; x0 += p) {
      const int y1 = std::min(height, y0 + p), x1 = std::min(width, x0 + p);
      double s = 0, s2 = 0;
      for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
          const double v = pixels[static_cast<size_t>(y) * width + x];
          s += v;
          s2 += v * v;
        }
      }
      const double count = static_cast<double>((y1 - y0) * (x1 - x0));
      const double m = s / count;
      const double sd = std::sqrt(std::max(0.0, s2 / count - m * m));
      // A flat patch (sd under half a grey level) carries no pattern: it stays at 128.
      if (sd < 0.5) continue;
      for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
          const double z = (pixels[static_cast<size_t>(y) * width + x] - m) / sd;
          f.bytes[static_cast<size_t>(y) * stride + x] =
              static_cast<uint8_t>(std::clamp(std::lround(128 + 32 * z), 0L, 255L));
        }
      }
    }
  }
  return f;
}

std::vector<uint8_t> ResizeByArea(const uint8_t* pixels, int width, int height, int to_width,
                                  int to_height) {
  std::vector<uint8_t> out(static_cast<size_t>(to_width) * to_height);
  // Output pixel x covers input [x * sx, (x + 1) * sx); each input pixel it touches counts by
  // the length of the overlap (separably in x and y).
  const double sx = static_cast<double>(width) / to_width;
  const double sy = static_cast<double>(height) / to_height;
  struct Span {
    int first = 0;
    std::vector<double> weights;
  };
  auto spans = [](int to, double scale, int limit) {
    std::vector<Span> out(to);
    for (int o = 0; o < to; ++o) {
      const double a = o * scale, b = (o + 1) * scale;
      const int first = static_cast<int>(std::floor(a));
      const int last = std::min(limit - 1, static_cast<int>(std::ceil(b)) - 1);
      out[o].first = first;
      for (int i = first; i <= last; ++i) {
        out[o].weights.push_back(std::min<double>(b, i + 1) - std::max<double>(a, i));
      }
    }
    return out;
  };
  const std::vector<Span> xs = spans(to_width, sx, width), ys = spans(to_height, sy, height);
  for (int oy = 0; oy < to_height; ++oy) {
    for (int ox = 0; ox < to_width; ++ox) {
      double sum = 0, area = 0;
      for (size_t j = 0; j < ys[oy].weights.size(); ++j) {
        const uint8_t* row = pixels + static_cast<size_t>(ys[oy].first + j) * width;
        for (size_t i = 0; i < xs[ox].weights.size(); ++i) {
          const double w = ys[oy].weights[j] * xs[ox].weights[i];
          sum += w * row[xs[ox].first + i];
          area += w;
        }
      }
      out[static_cast<size_t>(oy) * to_width + ox] =
          static_cast<uint8_t>(std::clamp(std::lround(sum / area), 0L, 255L));
    }
  }
  return out;
}

PreparedFrame PrepareFrame(const uint8_t* pixels, int width, int height,
                           const SequenceMatcherOptions& options) {
  if (options.image_width_px > 0 && width > 0 && height > 0 &&
      (width != options.image_width_px || height != options.image_height_px)) {
    const std::vector<uint8_t> resized =
        ResizeByArea(pixels, width, height, options.image_width_px, options.image_height_px);
    return PrepareFrame(resized.data(), options.image_width_px, options.image_height_px,
                        options.patch_px, options.blank_contrast);
  }
  return PrepareFrame(pixels, width, height, options.patch_px, options.blank_contrast);
}

double FrameDifference(const PreparedFrame& a, const PreparedFrame& b) {
  const size_t n = std::min(a.bytes.size(), b.bytes.size());
  const double pixels = static_cast<double>(a.width) * a.height;
  return pixels > 0 ? static_cast<double>(kSad(a.bytes.data(), b.bytes.data(), n)) / pixels : 0.0;
}

SequenceMatcher::SequenceMatcher(const SequenceMatcherOptions& options) : options_(options) {
  std::string error;
  if (!options_.IsValid(&error)) throw std::invalid_argument("sequence matcher: " + error);
}

Status SequenceMatcher::AddReference(PreparedFrame frame) {
  if (!references_.empty() &&
      (frame.width != references_[0].width || frame.height != references_[0].height)) {
    return Status::Error("reference " + std::to_string(references_.size()) + " is " +
                         std::to_string(frame.width) + "x" + std::to_string(frame.height) +
                         ", the first was " + std::to_string(references_[0].width) + "x" +
                         std::to_string(references_[0].height));
  }
  references_.push_back(std::move(frame));
  return Status::Ok();
}

Status SequenceMatcher::SetState(State state) {
  for (size_t i = 0; i < state.references.size(); ++i) {
    const PreparedFrame& f = state.references[i];
    const PreparedFrame& first = state.references[0];
    const size_t stride = (static_cast<size_t>(std::max(f.width, 0)) + kRowAlignment - 1) /
                          kRowAlignment * kRowAlignment;
    if (f.width < 0 || f.height < 0 || f.width != first.width || f.height != first.height ||
        f.bytes.size() != stride * static_cast<size_t>(f.height)) {
      return Status::Error("sequence matcher state: reference " + std::to_string(i) +
                           " has the wrong size");
    }
  }
  if (state.rows.size() > static_cast<size_t>(options_.sequence_length)) {
    return Status::Error("sequence matcher state: " + std::to_string(state.rows.size()) +
                         " query rows, more than sequence_length");
  }
  for (const Row& row : state.rows) {
    if (row.enhanced.size() > state.references.size() || !std::isfinite(row.neutral) ||
        !std::all_of(row.enhanced.begin(), row.enhanced.end(),
                     [](float v) { return std::isfinite(v); })) {
      return Status::Error(
          "sequence matcher state: a query row is longer than the references "
          "or not finite");
    }
  }
  references_ = std::move(state.references);
  rows_ = std::move(state.rows);
  return Status::Ok();
}

StatusOr<SequenceMatcher::Result> SequenceMatcher::AddQuery(const PreparedFrame& frame,
                                                            int candidates, int searchable) {
  const int n = static_cast<int>(references_.size());
  const int answers = searchable < 0 ? n : std::min(n, searchable);
  if (n > 0 && (frame.width != references_[0].width || frame.height != references_[0].height)) {
    return Status::Error("query is " + std::to_string(frame.width) + "x" +
                         std::to_string(frame.height) + ", the references are " +
                         std::to_string(references_[0].width) + "x" +
                         std::to_string(references_[0].height));
  }
  std::vector<float> differences(n);
  for (int r = 0; r < n; ++r) {
    differences[r] = static_cast<float>(FrameDifference(frame, references_[r]));
  }
  return Match(std::move(differences), frame.blank, candidates, answers);
}

StatusOr<SequenceMatcher::Result> SequenceMatcher::AddQueryDifferences(
    std::vector<float> differences, bool blank, int candidates, int searchable) {
  const int n = static_cast<int>(references_.size());
  if (differences.size() != references_.size()) {
    return Status::Error("a query row of " + std::to_string(differences.size()) +
                         " differences for " + std::to_string(n) + " references");
  }
  for (size_t r = 0; r < differences.size(); ++r) {
    if (!std::isfinite(differences[r]) || differences[r] < 0.0f) {
      return Status::Error("difference to reference " + std::to_string(r) +
                           " is negative or not finite");
    }
  }
  return Match(std::move(differences), blank, candidates,
               searchable < 0 ? n : std::min(n, searchable));
}

SequenceMatcher::Result SequenceMatcher::Match(std::vector<float> differences, bool blank,
                                               int candidates, int answers) {
  const int n = static_cast<int>(references_.size());
  Result result;
  result.differences = std::move(differences);

  // Contrast enhancement along the references (eq. 1): each difference less the mean of its
  // window, over the window's standard deviation; blank references take no part.
  Row row;
  row.blank = blank;
  row.enhanced.assign(n, 0.0f);
  row.neutral = 0.0f;
  std::vector<double> prefix(n + 1, 0.0), prefix_sq(n + 1, 0.0), prefix_count(n + 1, 0.0);
  for (int r = 0; r < n; ++r) {
    const bool use = !references_[r].blank;
    const double d = result.differences[r];
    prefix[r + 1] = prefix[r] + (use ? d : 0.0);
    prefix_sq[r + 1] = prefix_sq[r] + (use ? d * d : 0.0);
    prefix_count[r + 1] = prefix_count[r] + (use ? 1.0 : 0.0);
  }
  const int half = options_.contrast_window / 2;
  for (int r = 0; r < n; ++r) {
    if (references_[r].blank) continue;
    if (options_.contrast_window == 0) {
      row.enhanced[r] = result.differences[r];
      continue;
    }
    const int lo = std::max(0, r - half), hi = std::min(n, r + half + 1);
    const double count = prefix_count[hi] - prefix_count[lo];
    const double mean = (prefix[hi] - prefix[lo]) / count;
    const double var = std::max(0.0, (prefix_sq[hi] - prefix_sq[lo]) / count - mean * mean);
    const double sd = std::sqrt(var);
    row.enhanced[r] = sd > 1e-9 ? static_cast<float>((result.differences[r] - mean) / sd) : 0.0f;
  }
  if (options_.contrast_window == 0) {
    // Raw differences: the neutral term is the row's mean over the non-blank references.
    row.neutral = prefix_count[n] > 0 ? static_cast<float>(prefix[n] / prefix_count[n]) : 0.0f;
    for (int r = 0; r < n; ++r) {
      if (references_[r].blank) row.enhanced[r] = row.neutral;
    }
  }
  rows_.push_back(std::move(row));
  while (static_cast<int>(rows_.size()) > options_.sequence_length) rows_.pop_front();

  const double inf = std::numeric_limits<double>::infinity();
  // Single frame: the raw differences, blank references excluded.
  {
    std::vector<double> score(n, inf);
    if (!blank) {
      for (int r = 0; r < answers; ++r) {
        if (!references_[r].blank) score[r] = result.differences[r];
      }
    }
    result.single = MatchOf(score, candidates, options_.exclusion_window);
  }
  result.sequence = Search(0, answers, candidates);
  return result;
}

SequenceMatch SequenceMatcher::MatchAt(int back, int candidates) const {
  return Search(back, static_cast<int>(references_.size()), candidates);
}

// For each reference i, the best straight line through the stored rows that passes reference i
// at the row `back` frames before the newest (0: the newest, SeqSLAM's online search); the score
// is the mean enhanced difference over the non-blank query rows. A line's term at a blank
// reference, before the route's start or past its end (or past the references a row has seen)
// is neutral (the row's mean: 0 once enhanced), so that every line averages as many terms: a
// line through a tunnel is neither favoured nor barred. Only references below `answers` are
// answers.
SequenceMatch SequenceMatcher::Search(int back, int answers, int candidates) const {
  const int rows = static_cast<int>(rows_.size());
  std::vector<double> score(answers, std::numeric_limits<double>::infinity());
  if (back >= 0 && back < rows && !rows_[rows - 1 - back].blank) {
    const int steps = options_.velocity_steps;
    std::vector<float> sum(answers);
    int used = 0;
    for (const Row& r : rows_) used += !r.blank;
    for (int s = 0; s < steps; ++s) {
      const double v = steps == 1
                           ? options_.min_velocity
                           : options_.min_velocity +
                                 (options_.max_velocity - options_.min_velocity) * s / (steps - 1);
      std::fill(sum.begin(), sum.end(), 0.0f);
      for (int k = 0; k < rows; ++k) {
        const Row& row = rows_[rows - 1 - k];  // query frame newest - k
        if (row.blank) continue;
        // The line meets reference i - offset at this row (offset < 0 for rows newer than the
        // one it is reported at).
        const long offset = std::lround(v * (k - back));
        const int size = static_cast<int>(row.enhanced.size());
        const int lo = static_cast<int>(std::clamp<long>(offset, 0, answers));
        const int hi = static_cast<int>(std::clamp<long>(offset + size, lo, answers));
        const float* e = row.enhanced.data();
        for (int i = 0; i < lo; ++i) sum[i] += row.neutral;
        for (int i = lo; i < hi; ++i) sum[i] += e[i - offset];
        for (int i = hi; i < answers; ++i) sum[i] += row.neutral;
      }
      for (int i = 0; i < answers; ++i) {
        if (references_[i].blank) continue;
        score[i] = std::min(score[i], static_cast<double>(sum[i]) / used);
      }
    }
  }
  return MatchOf(score, candidates, options_.exclusion_window);
}

}  // namespace ratslam::sensors
