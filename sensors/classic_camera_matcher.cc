#include "sensors/classic_camera_matcher.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <tuple>

#if defined(__x86_64__)
#include <immintrin.h>
#define RATSLAM_HAVE_X86_SIMD 1
#endif

#include "common/circular.h"

namespace ratslam::sensors {

// Shifted, masked copies of the query, one per compared offset, in the stored-template layout.
struct ClassicCameraMatcher::PreparedQuery {
  std::vector<uint8_t> rows;   // shifts * height * stride
  std::vector<uint8_t> masks;  // shifts * stride: 0xFF where the offset overlaps
  std::vector<int> overlap_columns;
  // For the lower bound: per shift the overlapping template columns [first, last) (contiguous:
  // all of them when panoramic) and the query's column sums they meet (shifts * width).
  std::vector<int> first_column, last_column;
  std::vector<int32_t> column_sums;
  std::vector<int64_t> overlap_sums;  // per shift: the query's sum over the overlap
  // Per shift: the query's sums over the overlap cut into kIndexRuns runs of columns (as the
  // index cuts the templates' overlap).
  std::vector<int64_t> run_sums;
};

namespace {

// The index tests sums over this many runs of the overlap's columns (|sum of differences| <=
// sum of |differences| per run, so their L1 distance is a lower bound as the column bound is).
// More runs make a tighter test that costs more; on the synthetic loop at a 0.004 threshold, 6
// runs leave about 1 % of templates for the column bound where the total leaves 20-40 %, and 8
// fill one 256-bit register.
constexpr int kIndexRuns = 8;

// The template columns [first, last) a shift overlaps: all of them in a panorama. Prepare (query
// side) and the index (template side) must agree on it.
std::pair<int, int> OverlapOf(int shift, int width, bool panoramic) {
  if (panoramic) return {0, width};
  return {std::max(0, -shift), std::min(width, width - shift)};
}

// Sums of `columns` over the kIndexRuns runs that cut [first, last), appended to `out`: the same
// cut on the query's side and the templates'.
template <typename Sum>
void AppendRunSums(const int32_t* columns, int first, int last, std::vector<Sum>* out) {
  const int span = last - first;
  for (int j = 0; j < kIndexRuns; ++j) {
    Sum sum = 0;
    for (int u = first + span * j / kIndexRuns; u < first + span * (j + 1) / kIndexRuns; ++u) {
      sum += columns[u];
    }
    out->push_back(sum);
  }
}

// Whether the AVX2 kernels can run here (asked once).
bool HaveAvx2() {
#if defined(RATSLAM_HAVE_X86_SIMD)
  static const bool kAvx2 = __builtin_cpu_supports("avx2");
  return kAvx2;
#else
  return false;
#endif
}

// Marks in `marked` (a bitmap by id) the records whose sums over runs of columns, kIndexRuns
// per record, are within `limit` of the query's in L1 (each sum and the query's < 2^31).
void MarkRunsWithinPortable(const int32_t* runs, const uint32_t* ids, size_t count,
                            const int32_t* query_runs, uint32_t limit, uint64_t* marked) {
  for (size_t r = 0; r < count; ++r) {
    uint32_t bound = 0;  // < 2^32
    for (int j = 0; j < kIndexRuns; ++j) {
      bound += static_cast<uint32_t>(std::abs(runs[r * kIndexRuns + j] - query_runs[j]));
    }
    if (bound <= limit) marked[ids[r] / 64] |= uint64_t{1} << (ids[r] % 64);
  }
}

#if defined(RATSLAM_HAVE_X86_SIMD)
// The same, eight records at a time (horizontal adds turn eight records' differences into one
// register of their sums).
__attribute__((target("avx2"))) void MarkRunsWithinAvx2(const int32_t* runs, const uint32_t* ids,
                                                        size_t count, const int32_t* query_runs,
                                                        uint32_t limit, uint64_t* marked) {
  static_assert(kIndexRuns == 8, "one record per 256-bit register");
  const __m256i query = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(query_runs));
  const __m256i limits = _mm256_set1_epi32(static_cast<int32_t>(limit));
  size_t r = 0;
  for (; r + 8 <= count; r += 8) {
    __m256i d[8];
    for (int i = 0; i < 8; ++i) {
      const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(runs + (r + i) * 8));
      d[i] = _mm256_abs_epi32(_mm256_sub_epi32(v, query));
    }
    // hadd works within 128-bit halves: ab's low half holds records 0-3's sums over runs 0-3,
    // its high half their sums over runs 4-7; ce the same for records 4-7. (Sums wrap modulo
    // 2^32 as unsigned values, which they are: < 2^32.)
    const __m256i a = _mm256_hadd_epi32(d[0], d[1]), b = _mm256_hadd_epi32(d[2], d[3]);
    const __m256i c = _mm256_hadd_epi32(d[4], d[5]), e = _mm256_hadd_epi32(d[6], d[7]);
    const __m256i ab = _mm256_hadd_epi32(a, b), ce = _mm256_hadd_epi32(c, e);
    const __m256i all = _mm256_add_epi32(_mm256_permute2x128_si256(ab, ce, 0x20),
                                         _mm256_permute2x128_si256(ab, ce, 0x31));  // records 0-7
    const __m256i within = _mm256_cmpeq_epi32(_mm256_min_epu32(all, limits), all);
    for (uint32_t bits = static_cast<uint32_t>(_mm256_movemask_ps(_mm256_castsi256_ps(within)));
         bits != 0; bits &= bits - 1) {
      const uint32_t id = ids[r + std::countr_zero(bits)];
      marked[id / 64] |= uint64_t{1} << (id % 64);
    }
  }
  MarkRunsWithinPortable(runs + r * 8, ids + r, count - r, query_runs, limit, marked);
}
#endif

// The largest integer bound whose scaled value is <= `best` (a bound above it cannot win; one at
// it may tie): the tests on sums are then integer comparisons.
int64_t LimitFor(double best, double scale) {
  if (!(best >= 0.0)) return -1;  // negative or NaN: no bound (>= 0) can win
  const double ratio = std::floor(best / scale);
  if (!(ratio < 9e18)) return std::numeric_limits<int64_t>::max();
  int64_t limit = static_cast<int64_t>(ratio);
  while (static_cast<double>(limit + 1) * scale <= best) ++limit;
  while (limit >= 0 && static_cast<double>(limit) * scale > best) --limit;
  return limit;
}

// Local contrast normalisation maps z-scores to intensities as 0.5 + z / kPatchZSpan, so that
// +-3 standard deviations span the 0..1 range.
constexpr double kPatchZSpan = 6.0;

uint8_t Quantise(double value) {
  return static_cast<uint8_t>(std::lround(std::clamp(value, 0.0, 1.0) * 255.0));
}

ClassicCameraMatcher::PreparedQuery Prepare(const std::vector<uint8_t>& query,
                                            const std::vector<int>& shifts, int width, int height,
                                            int stride, bool panoramic) {
  ClassicCameraMatcher::PreparedQuery p;
  const size_t per_shift = static_cast<size_t>(height) * stride;
  p.rows.assign(shifts.size() * per_shift, 0);
  p.masks.assign(shifts.size() * stride, 0);
  for (size_t k = 0; k < shifts.size(); ++k) {
    const int s = shifts[k];
    int overlap = 0;
    for (int u = 0; u < width; ++u) {
      // Template column u meets query column u + s.
      int source = u + s;
      if (panoramic) {
        source = WrapIndex(source, width);
      } else if (source < 0 || source >= width) {
        continue;
      }
      ++overlap;
      p.masks[k * stride + u] = 0xFF;
      for (int r = 0; r < height; ++r) {
        p.rows[k * per_shift + static_cast<size_t>(r) * stride + u] =
            query[static_cast<size_t>(r) * stride + source];
      }
    }
    p.overlap_columns.push_back(overlap);
    const auto [first, last] = OverlapOf(s, width, panoramic);
    p.first_column.push_back(first);
    p.last_column.push_back(last);
  }
  p.column_sums.assign(shifts.size() * width, 0);
  for (size_t k = 0; k < shifts.size(); ++k) {
    for (int u = 0; u < width; ++u) {
      int32_t sum = 0;
      for (int r = 0; r < height; ++r)
        sum += p.rows[k * per_shift + static_cast<size_t>(r) * stride + u];
      p.column_sums[k * width + u] = sum;
    }
    int64_t overlap = 0;
    for (int u = p.first_column[k]; u < p.last_column[k]; ++u)
      overlap += p.column_sums[k * width + u];
    p.overlap_sums.push_back(overlap);
    AppendRunSums(p.column_sums.data() + k * width, p.first_column[k], p.last_column[k],
                  &p.run_sums);
  }
  return p;
}

// Column sums of a stored template (width values), then their running sums (width + 1).
void AppendColumnSums(const uint8_t* t, int width, int height, int stride,
                      std::vector<int32_t>* out) {
  const size_t start = out->size();
  for (int u = 0; u < width; ++u) {
    int32_t sum = 0;
    for (int r = 0; r < height; ++r) sum += t[static_cast<size_t>(r) * stride + u];
    out->push_back(sum);
  }
  // Exact when width * height * 255 < 2^31 (where the scan uses them); wraps beyond.
  int64_t running = 0;
  out->push_back(0);
  for (int u = 0; u < width; ++u) {
    running += (*out)[start + u];
    out->push_back(static_cast<int32_t>(running));
  }
}

// Sum of absolute differences between a stored template (masked) and one prepared shift.
// Rows are padded to a multiple of 32 bytes with zeros.
inline uint32_t MaskedSadPortable(const uint8_t* stored, const uint8_t* prepared,
                                  const uint8_t* mask, int height, int stride) {
#if defined(RATSLAM_HAVE_X86_SIMD)
  __m128i acc = _mm_setzero_si128();
  for (int r = 0; r < height; ++r) {
    const uint8_t* t = stored + static_cast<size_t>(r) * stride;
    const uint8_t* q = prepared + static_cast<size_t>(r) * stride;
    for (int c = 0; c < stride; c += 16) {
      const __m128i tv = _mm_and_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(t + c)),
                                       _mm_loadu_si128(reinterpret_cast<const __m128i*>(mask + c)));
      const __m128i qv = _mm_loadu_si128(reinterpret_cast<const __m128i*>(q + c));
      acc = _mm_add_epi64(acc, _mm_sad_epu8(tv, qv));
    }
  }
  return static_cast<uint32_t>(_mm_cvtsi128_si32(acc) +
                               _mm_cvtsi128_si32(_mm_unpackhi_epi64(acc, acc)));
#else
  uint32_t sum = 0;
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < stride; ++c) {
      const int t = stored[static_cast<size_t>(r) * stride + c] & mask[c];
      sum += std::abs(t - prepared[static_cast<size_t>(r) * stride + c]);
    }
  }
  return sum;
#endif
}

#if defined(RATSLAM_HAVE_X86_SIMD)
__attribute__((target("avx2"))) inline uint32_t MaskedSadAvx2(const uint8_t* stored,
                                                              const uint8_t* prepared,
                                                              const uint8_t* mask, int height,
                                                              int stride) {
  __m256i acc = _mm256_setzero_si256();
  for (int r = 0; r < height; ++r) {
    const uint8_t* t = stored + static_cast<size_t>(r) * stride;
    const uint8_t* q = prepared + static_cast<size_t>(r) * stride;
    for (int c = 0; c < stride; c += 32) {
      const __m256i tv =
          _mm256_and_si256(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(t + c)),
                           _mm256_loadu_si256(reinterpret_cast<const __m256i*>(mask + c)));
      const __m256i qv = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(q + c));
      acc = _mm256_add_epi64(acc, _mm256_sad_epu8(tv, qv));
    }
  }
  const __m128i sum = _mm_add_epi64(_mm256_castsi256_si128(acc), _mm256_extracti128_si256(acc, 1));
  return static_cast<uint32_t>(_mm_cvtsi128_si32(sum) +
                               _mm_cvtsi128_si32(_mm_unpackhi_epi64(sum, sum)));
}
#endif

// Calls visit(template id, smallest difference over the shifts) for every stored template, with
// the SAD kernel `Sad`. The minimum is taken without branches: a per-shift argmin mispredicts.
template <uint32_t (*Sad)(const uint8_t*, const uint8_t*, const uint8_t*, int, int), typename Visit>
#if defined(RATSLAM_HAVE_X86_SIMD)
__attribute__((target("avx2")))
#endif
void ForEachTemplate(const uint8_t* base, uint32_t count, size_t bytes_per_template,
                     const ClassicCameraMatcher::PreparedQuery& prepared, const std::vector<double>& scale,
                     const std::vector<int>& shifts, int height, int stride, Visit&& visit) {
  const size_t per_shift = static_cast<size_t>(height) * stride;
  for (uint32_t id = 0; id < count; ++id) {
    const uint8_t* t = base + id * bytes_per_template;
    double best = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < shifts.size(); ++k) {
      const uint32_t sad = Sad(t, prepared.rows.data() + k * per_shift,
                               prepared.masks.data() + k * stride, height, stride);
      best = std::min(best, sad * scale[k]);
    }
    visit(id, best);
  }
}

// The smallest difference over the shifts to one template.
template <uint32_t (*Sad)(const uint8_t*, const uint8_t*, const uint8_t*, int, int)>
#if defined(RATSLAM_HAVE_X86_SIMD)
__attribute__((target("avx2")))
#endif
inline double
TemplateBest(const uint8_t* t, const ClassicCameraMatcher::PreparedQuery& prepared,
             const std::vector<double>& scale, size_t shifts, int height, int stride) {
  const size_t per_shift = static_cast<size_t>(height) * stride;
  double best = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < shifts; ++k) {
    const uint32_t sad = Sad(t, prepared.rows.data() + k * per_shift,
                             prepared.masks.data() + k * stride, height, stride);
    best = std::min(best, sad * scale[k]);
  }
  return best;
}

// The best so far: (difference, id) compared lexicographically, so that among equal differences
// the lowest id wins whatever the visiting order. Starts at (cutoff, kNoTemplate): a template
// whose difference equals the cutoff still wins.
constexpr int32_t kNoTemplate = std::numeric_limits<int32_t>::max();

struct Best {
  double difference;
  int32_t id = kNoTemplate;
  bool Beaten(double d, uint32_t by) const {
    return d < difference || (d == difference && static_cast<int64_t>(by) < id);
  }
};

// The best template among `candidates` (all ids in order when null), skipping every template
// whose exact lower bound cannot beat the best so far. The bound: per column, |sum of template
// column - sum of query column| <= the column's sum of absolute differences (triangle
// inequality), so the bound's sum over the overlap is <= the SAD for each shift, and scaling by
// the same positive factor keeps the order (rounding is monotone). A template whose bound does
// not beat the best has a difference that does not either: the result equals the full scan's.
template <uint32_t (*Sad)(const uint8_t*, const uint8_t*, const uint8_t*, int, int),
          typename Sum>
#if defined(RATSLAM_HAVE_X86_SIMD)
__attribute__((target("avx2")))
#endif
void BestWithBound(const uint8_t* base, uint32_t count, size_t bytes_per_template,
                   const int32_t* template_column_sums, int width,
                   const ClassicCameraMatcher::PreparedQuery& prepared,
                   const std::vector<double>& scale, size_t shifts, int height, int stride,
                   int64_t skip, const std::vector<uint32_t>* candidates, Best* best,
                   uint64_t* full_comparisons) {
  // Per shift the largest integer bound that may still win (LimitFor).
  std::vector<int64_t> limits(shifts);
  auto set_limits = [&] {
    for (size_t k = 0; k < shifts; ++k) limits[k] = LimitFor(best->difference, scale[k]);
  };
  set_limits();
  const size_t n = candidates ? candidates->size() : count;
  for (size_t i = 0; i < n; ++i) {
    const uint32_t id = candidates ? (*candidates)[i] : static_cast<uint32_t>(i);
    if (id == skip) continue;
    const int32_t* columns = template_column_sums + static_cast<size_t>(id) * (2 * width + 1);
    const int32_t* prefix = columns + width;  // width + 1 running sums of the columns
    bool may_win = false;
    for (size_t k = 0; k < shifts && !may_win; ++k) {
      // First the total over the overlap (|sum of differences| <= sum of |differences|), in
      // constant time from prefix sums; then the column bound. (The sums over runs of columns
      // are tested where the index picks candidates; here, on a scan of all, they cost more than
      // they save when templates are normalised.)
      if constexpr (sizeof(Sum) == 4) {  // running sums are exact only then
        const int first = prepared.first_column[k], last = prepared.last_column[k];
        const int64_t total =
            static_cast<int64_t>(prefix[last]) - prefix[first] - prepared.overlap_sums[k];
        if ((total < 0 ? -total : total) > limits[k]) continue;
      }
      const int32_t* query = prepared.column_sums.data() + k * width;
      Sum bound = 0;  // vectorises when Sum is 32 bits
      for (int u = prepared.first_column[k]; u < prepared.last_column[k]; ++u) {
        bound += static_cast<Sum>(std::abs(columns[u] - query[u]));
      }
      may_win = best->Beaten(static_cast<double>(bound) * scale[k], id);
    }
    if (!may_win) continue;
    ++*full_comparisons;
    const double difference =
        TemplateBest<Sad>(base + id * bytes_per_template, prepared, scale, shifts, height, stride);
    if (best->Beaten(difference, id)) {
      *best = {difference, static_cast<int32_t>(id)};
      set_limits();
    }
  }
}

template <uint32_t (*Sad)(const uint8_t*, const uint8_t*, const uint8_t*, int, int)>
void BestWithBound(const uint8_t* base, uint32_t count, size_t bytes_per_template,
                   const int32_t* template_column_sums, int width,
                   const ClassicCameraMatcher::PreparedQuery& prepared,
                   const std::vector<double>& scale, size_t shifts, int height, int stride,
                   int64_t skip, const std::vector<uint32_t>* candidates, Best* best,
                   uint64_t* full_comparisons) {
  // The bound is at most width * height * 255: 32 bits suffice below 8.4 million pixels.
  const bool fits_32 = static_cast<uint64_t>(width) * height * 255 < (uint64_t{1} << 31);
  if (fits_32) {
    BestWithBound<Sad, uint32_t>(base, count, bytes_per_template, template_column_sums, width,
                                 prepared, scale, shifts, height, stride, skip, candidates, best,
                                 full_comparisons);
  } else {
    BestWithBound<Sad, uint64_t>(base, count, bytes_per_template, template_column_sums, width,
                                 prepared, scale, shifts, height, stride, skip, candidates, best,
                                 full_comparisons);
  }
}

}  // namespace

bool ClassicCameraOptions::IsValid(std::string* error) const {
  auto fail = [error](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (!schema::CheckFields(*this, error)) return false;
  if (crop_right_px != -1 && crop_right_px <= crop_left_px) {
    return fail("crop_right_px: must be -1 or greater than crop_left_px");
  }
  if (crop_bottom_px != -1 && crop_bottom_px <= crop_top_px) {
    return fail("crop_bottom_px: must be -1 or greater than crop_top_px");
  }
  if (shift_px >= template_width_px) return fail("shift_px: must be less than template_width_px");
  return true;
}

ClassicCameraMatcher::ClassicCameraMatcher(const ClassicCameraOptions& options)
    : options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("ClassicCameraOptions: " + error);
  row_stride_ = (options.template_width_px + 31) / 32 * 32;  // whole 32-byte SIMD words
  bytes_per_template_ = static_cast<size_t>(row_stride_) * options.template_height_px;
  if (options.panoramic) {
    // The whole ring, as OpenRatSLAM searches a panorama (offsets 0, step, 2 step, ... of the
    // template's columns; a smaller offset wins a tie): a place seen the other way round
    // matches. Template column u meets query column u - offset.
    for (int offset = 0; offset < options.template_width_px; offset += options.shift_step_px) {
      shifts_.push_back(-offset);
    }
  } else {
    for (int s = -options.shift_px; s <= options.shift_px; s += options.shift_step_px) {
      shifts_.push_back(s);
    }
  }
  // The template columns each shift overlaps (as Prepare computes them), one index per distinct
  // overlap: a panorama has one, a shift range one per shift.
  const int w = options.template_width_px;
  for (int s : shifts_) {
    const auto [first, last] = OverlapOf(s, w, options.panoramic);
    size_t entry = 0;
    while (entry < total_buckets_.size() &&
           (total_buckets_[entry].first != first || total_buckets_[entry].last != last)) {
      ++entry;
    }
    if (entry == total_buckets_.size()) {
      TotalBuckets index;
      index.first = first;
      index.last = last;
      const int64_t largest = int64_t{255} * options.template_height_px * (last - first);
      index.bucket_width = largest / kTotalBuckets + 1;
      index.buckets.resize(kTotalBuckets);
      total_buckets_.push_back(std::move(index));
    }
    shift_overlap_.push_back(static_cast<int>(entry));
  }
}

StatusOr<std::vector<uint8_t>> ClassicCameraMatcher::MakeTemplate(
    const GrayImageView& image) const {
  const int right = options_.crop_right_px < 0 ? image.width : options_.crop_right_px;
  const int bottom = options_.crop_bottom_px < 0 ? image.height : options_.crop_bottom_px;
  const int crop_w = right - options_.crop_left_px;
  const int crop_h = bottom - options_.crop_top_px;
  const int w = options_.template_width_px;
  const int h = options_.template_height_px;
  // A crop edge outside the image is the configuration's fault, not the image's: name the key.
  for (const auto& [key, edge, size] :
       {std::tuple<const char*, int, int>{"crop_left_px", options_.crop_left_px, image.width},
        {"crop_top_px", options_.crop_top_px, image.height},
        {"crop_right_px", options_.crop_right_px, image.width},
        {"crop_bottom_px", options_.crop_bottom_px, image.height}}) {
    if (edge > size) {
      return Status::Error("[camera] " + std::string(key) + " = " + std::to_string(edge) +
                           " lies outside the " + std::to_string(image.width) + "x" +
                           std::to_string(image.height) + " px image");
    }
  }
  if (image.pixels == nullptr || right > image.width || bottom > image.height) {
    return Status::Error("image of " + std::to_string(image.width) + "x" +
                         std::to_string(image.height) + " px is smaller than the crop");
  }
  if (crop_w < w || crop_h < h) {
    return Status::Error("crop of " + std::to_string(crop_w) + "x" + std::to_string(crop_h) +
                         " px is smaller than the " + std::to_string(w) + "x" + std::to_string(h) +
                         " template");
  }
  // Block means over integer block boundaries.
  std::vector<double> values(static_cast<size_t>(w) * h);
  for (int ty = 0; ty < h; ++ty) {
    const int y0 = options_.crop_top_px + ty * crop_h / h;
    const int y1 = options_.crop_top_px + (ty + 1) * crop_h / h;
    for (int tx = 0; tx < w; ++tx) {
      const int x0 = options_.crop_left_px + tx * crop_w / w;
      const int x1 = options_.crop_left_px + (tx + 1) * crop_w / w;
      uint64_t sum = 0;
      for (int y = y0; y < y1; ++y) {
        const uint8_t* row = image.pixels + static_cast<size_t>(y) * image.stride_bytes;
        for (int x = x0; x < x1; ++x) sum += row[x];
      }
      values[static_cast<size_t>(ty) * w + tx] =
          static_cast<double>(sum) / (255.0 * (x1 - x0) * (y1 - y0));
    }
  }
  if (options_.global_normalisation_mean > 0.0) {
    double mean = 0.0;
    for (double v : values) mean += v;
    mean /= static_cast<double>(values.size());
    if (mean > 0.0) {
      for (double& v : values) v *= options_.global_normalisation_mean / mean;
    }
  }
  if (options_.patch_normalisation_radius_px > 0) {
    const int p = options_.patch_normalisation_radius_px;
    std::vector<double> normalised(values.size());
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        double sum = 0.0, sum2 = 0.0;
        int n = 0;
        for (int yy = std::max(0, y - p); yy <= std::min(h - 1, y + p); ++yy) {
          for (int xx = std::max(0, x - p); xx <= std::min(w - 1, x + p); ++xx) {
            const double v = values[static_cast<size_t>(yy) * w + xx];
            sum += v;
            sum2 += v * v;
            ++n;
          }
        }
        const double mean = sum / n;
        const double sd = std::sqrt(std::max(0.0, sum2 / n - mean * mean));
        const double v = values[static_cast<size_t>(y) * w + x];
        normalised[static_cast<size_t>(y) * w + x] =
            sd > 1e-9 ? 0.5 + (v - mean) / sd / kPatchZSpan : 0.5;
      }
    }
    values.swap(normalised);
  }
  std::vector<uint8_t> result(bytes_per_template_, 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      result[static_cast<size_t>(y) * row_stride_ + x] =
          Quantise(values[static_cast<size_t>(y) * w + x]);
    }
  }
  return result;
}

ClassicCameraMatcher::PreparedQuery ClassicCameraMatcher::PrepareQuery(
    const std::vector<uint8_t>& query) const {
  return Prepare(query, shifts_, options_.template_width_px, options_.template_height_px,
                 row_stride_, options_.panoramic);
}

template <typename Visit>
void ClassicCameraMatcher::VisitTemplates(const PreparedQuery& prepared, Visit&& visit) const {
  const int h = options_.template_height_px;
  std::vector<double> scale(shifts_.size());
  for (size_t k = 0; k < shifts_.size(); ++k) {
    scale[k] = 1.0 / (255.0 * h * prepared.overlap_columns[k]);
  }
  const uint8_t* base = state_.templates.data();
#if defined(RATSLAM_HAVE_X86_SIMD)
  if (HaveAvx2()) {
    ForEachTemplate<MaskedSadAvx2>(base, state_.template_count, bytes_per_template_, prepared,
                                   scale, shifts_, h, row_stride_, visit);
    return;
  }
#endif
  ForEachTemplate<MaskedSadPortable>(base, state_.template_count, bytes_per_template_, prepared,
                                     scale, shifts_, h, row_stride_, visit);
}

bool ClassicCameraMatcher::CandidatesWithin(const PreparedQuery& prepared,
                                            const std::vector<double>& scale, double radius,
                                            std::vector<uint32_t>* out) const {
  if (!(radius < std::numeric_limits<double>::max())) return false;  // infinite: scan all
  // Per shift the buckets whose totals lie within radius / scale of the query's over the same
  // columns: outside them the total alone puts the bound above the radius at this shift. One
  // unit of margin each side absorbs rounding.
  struct Window {
    size_t shift, first_bucket, last_bucket;  // buckets [first, last]
  };
  std::vector<Window> windows;
  size_t estimate = 0;  // a template counts once per shift it falls near at
  for (size_t k = 0; k < shifts_.size(); ++k) {
    const TotalBuckets& index = total_buckets_[static_cast<size_t>(shift_overlap_[k])];
    const double reach = radius / scale[k] + 1.0;
    const double query = static_cast<double>(prepared.overlap_sums[k]);
    const double width = static_cast<double>(index.bucket_width);
    const double top = width * static_cast<double>(index.buckets.size());
    if (query - reach >= top || query + reach < 0.0) continue;  // no bucket in reach
    const size_t lo = query - reach <= 0.0 ? 0 : static_cast<size_t>((query - reach) / width);
    const size_t hi = query + reach >= top ? index.buckets.size() - 1
                                           : static_cast<size_t>((query + reach) / width);
    for (size_t b = lo; b <= hi; ++b) estimate += index.buckets[b].ids.size();
    // As many as several scans of all: the plain scan is cheaper.
    if (estimate >= 4u * state_.template_count) return false;
    windows.push_back({k, lo, hi});
  }
  // In each window, the sums over runs of columns (kept beside the ids, so this reads memory in
  // order) leave the few templates the full bound must look at. Union in id order through a
  // bitmap.
  std::vector<uint64_t> marked((state_.template_count + 63) / 64, 0);
  [[maybe_unused]] const bool use_avx2 = HaveAvx2() && !force_portable_;
  for (const Window& window : windows) {
    const TotalBuckets& index = total_buckets_[static_cast<size_t>(shift_overlap_[window.shift])];
    const int64_t limit = LimitFor(radius, scale[window.shift]);
    int32_t query_runs[kIndexRuns];
    for (int j = 0; j < kIndexRuns; ++j) {
      query_runs[j] = static_cast<int32_t>(prepared.run_sums[window.shift * kIndexRuns + j]);
    }
    for (size_t b = window.first_bucket; b <= window.last_bucket; ++b) {
      const TotalBuckets::Bucket& bucket = index.buckets[b];
      if (bucket.runs.empty()) {  // sums too large for 32 bits: the total alone decides
        for (uint32_t id : bucket.ids) marked[id / 64] |= uint64_t{1} << (id % 64);
        continue;
      }
      const uint32_t limit32 =
          static_cast<uint32_t>(std::min<int64_t>(limit, std::numeric_limits<uint32_t>::max()));
#if defined(RATSLAM_HAVE_X86_SIMD)
      if (use_avx2) {
        MarkRunsWithinAvx2(bucket.runs.data(), bucket.ids.data(), bucket.ids.size(), query_runs,
                           limit32, marked.data());
        continue;
      }
#endif
      MarkRunsWithinPortable(bucket.runs.data(), bucket.ids.data(), bucket.ids.size(), query_runs,
                             limit32, marked.data());
    }
  }
  out->clear();
  for (size_t word = 0; word < marked.size(); ++word) {
    for (uint64_t bits = marked[word]; bits != 0; bits &= bits - 1) {
      out->push_back(static_cast<uint32_t>(word * 64 + std::countr_zero(bits)));
    }
  }
  return true;
}

TemplateComparison ClassicCameraMatcher::Compare(const std::vector<uint8_t>& query, int64_t hint,
                                                 double cutoff) const {
  TemplateComparison result;
  if (state_.template_count == 0 || query.size() != bytes_per_template_) return result;
  const int64_t seed = hint >= 0 && hint < state_.template_count ? hint : -1;
  const PreparedQuery prepared = PrepareQuery(query);
  const int h = options_.template_height_px;
  const int w = options_.template_width_px;
  std::vector<double> scale(shifts_.size());
  for (size_t k = 0; k < shifts_.size(); ++k) {
    scale[k] = 1.0 / (255.0 * h * prepared.overlap_columns[k]);
  }
  const uint8_t* base = state_.templates.data();
  const int32_t* sums = column_sums_.data();
  Best best{cutoff};
  std::vector<uint32_t> candidates;
  // The seed first (a template likely to be near the best: the bound then skips more and the
  // candidates are fewer), then the others.
  auto search = [&]<uint32_t (*Sad)(const uint8_t*, const uint8_t*, const uint8_t*, int, int)>() {
    if (seed >= 0) {
      ++full_comparisons_;
      const double difference = TemplateBest<Sad>(base + seed * bytes_per_template_, prepared,
                                                  scale, shifts_.size(), h, row_stride_);
      if (best.Beaten(difference, static_cast<uint32_t>(seed))) {
        best = {difference, static_cast<int32_t>(seed)};
      }
    }
    const bool narrowed = CandidatesWithin(prepared, scale, best.difference, &candidates);
    BestWithBound<Sad>(base, state_.template_count, bytes_per_template_, sums, w, prepared, scale,
                       shifts_.size(), h, row_stride_, seed, narrowed ? &candidates : nullptr,
                       &best, &full_comparisons_);
    bounds_checked_ += narrowed ? candidates.size() : state_.template_count;
  };
#if defined(RATSLAM_HAVE_X86_SIMD)
  if (HaveAvx2() && !force_portable_) {
    search.template operator()<MaskedSadAvx2>();
  } else {
    search.template operator()<MaskedSadPortable>();
  }
#else
  search.template operator()<MaskedSadPortable>();
#endif
  if (best.id == kNoTemplate) return result;  // nothing within the cutoff
  result.template_id = best.id;
  result.mean_difference = best.difference;
  // The winning shift: recomputed for the winning template only (the first shift attaining it).
  const uint8_t* t = state_.templates.data() + best.id * bytes_per_template_;
  for (size_t k = 0; k < shifts_.size(); ++k) {
    const uint32_t sad = MaskedSadPortable(t, prepared.rows.data() + k * h * row_stride_,
                                           prepared.masks.data() + k * row_stride_, h, row_stride_);
    // Same expression as the scan (sad * scale), so equality is exact.
    if (sad * scale[k] == result.mean_difference) {
      result.shift_px = shifts_[k];
      break;
    }
  }
  return result;
}

std::vector<double> ClassicCameraMatcher::Differences(const std::vector<uint8_t>& query) const {
  std::vector<double> differences;
  if (query.size() != bytes_per_template_) return differences;
  differences.reserve(state_.template_count);
  VisitTemplates(PrepareQuery(query), [&differences](uint32_t, double difference) {
    differences.push_back(difference);
  });
  return differences;
}

uint32_t ClassicCameraMatcher::Add(const std::vector<uint8_t>& query) {
  state_.templates.insert(state_.templates.end(), query.begin(), query.end());
  Index(state_.template_count);
  return state_.template_count++;
}

void ClassicCameraMatcher::Index(uint32_t id) {
  const int w = options_.template_width_px;
  AppendColumnSums(state_.templates.data() + id * bytes_per_template_, w,
                   options_.template_height_px, row_stride_, &column_sums_);
  const int32_t* columns = column_sums_.data() + static_cast<size_t>(id) * (2 * w + 1);
  // Runs of columns as Prepare cuts each shift's overlap; their sums fit 32 bits when the whole
  // template's does (as the scan's running sums).
  const bool fits_32 = int64_t{255} * w * options_.template_height_px < (int64_t{1} << 31);
  for (TotalBuckets& index : total_buckets_) {
    int64_t total = 0;  // exact: the running sums may wrap on huge templates
    for (int u = index.first; u < index.last; ++u) total += columns[u];
    const size_t b =
        std::min(static_cast<size_t>(total / index.bucket_width), index.buckets.size() - 1);
    TotalBuckets::Bucket& bucket = index.buckets[b];
    bucket.ids.push_back(id);
    if (fits_32) AppendRunSums(columns, index.first, index.last, &bucket.runs);
  }
}

StatusOr<ViewDecision> ClassicCameraMatcher::Observe(const GrayImageView& image, double time_s) {
  StatusOr<std::vector<uint8_t>> query = MakeTemplate(image);
  if (!query.ok()) return query.status();
  const TemplateComparison best = Compare(query.value(), last_template_, options_.match_threshold);
  ViewDecision decision;
  decision.time_s = time_s;
  if (best.template_id >= 0 && best.mean_difference <= options_.match_threshold) {
    decision.template_id = static_cast<uint32_t>(best.template_id);
    decision.is_new = false;
    if (options_.panoramic) {
      // The view turned left by shift columns of a 360-degree image (columns run clockwise).
      decision.heading_change_rad =
          WrapAngle(2.0 * std::numbers::pi * best.shift_px / options_.template_width_px);
    }
  } else {
    decision.template_id = Add(query.value());
    decision.is_new = true;
  }
  last_template_ = decision.template_id;
  return decision;
}

Status ClassicCameraMatcher::SetState(State state) {
  if (state.templates.size() != static_cast<size_t>(state.template_count) * bytes_per_template_) {
    return Status::Error("camera matcher state: template bytes do not match the template size");
  }
  state_ = std::move(state);
  last_template_ = -1;
  column_sums_.clear();
  for (TotalBuckets& index : total_buckets_) {
    for (TotalBuckets::Bucket& bucket : index.buckets) bucket = {};
  }
  for (uint32_t id = 0; id < state_.template_count; ++id) Index(id);
  return Status::Ok();
}

}  // namespace ratslam::sensors
