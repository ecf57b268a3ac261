// The classic RatSLAM camera front end (Milford and Wyeth 2008; the variant of OpenRatSLAM,
// Ball et al. 2013): crop, block-mean down-sampling to a small template, optional global and
// patch normalisation, then comparison with every stored template by mean absolute intensity
// difference over a range of column shifts. In panoramic mode every shift of the ring is tried
// (in steps of shift_step_px; shift_px is not used), shifts wrap around, and the best shift gives
// the heading change since the template was stored.
//
// Templates are stored as 8-bit intensities (0..255 for 0..1) so that the comparison runs on
// SIMD sum-of-absolute-differences instructions; the quantisation error (at most 1/510 per
// pixel) is far below useful match thresholds. Differences are reported on the 0..1 scale.
#ifndef RATSLAM_SENSORS_CLASSIC_CAMERA_MATCHER_H_
#define RATSLAM_SENSORS_CLASSIC_CAMERA_MATCHER_H_

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "common/schema.h"
#include "common/status.h"
#include "ratslam/local_view_cells.h"

namespace ratslam::sensors {

// A borrowed 8-bit grey image, rows top to bottom.
struct GrayImageView {
  int width = 0;
  int height = 0;
  int stride_bytes = 0;
  const uint8_t* pixels = nullptr;
};

struct ClassicCameraOptions {
  int crop_left_px = 0;                    // first image column used
  int crop_right_px = -1;                  // one past the last column used; -1: image width
  int crop_top_px = 0;                     // first image row used
  int crop_bottom_px = -1;                 // one past the last row used; -1: image height
  int template_width_px = 60;              // template columns after block-mean down-sampling
  int template_height_px = 10;             // template rows
  int shift_px = 5;                        // columns compared at offsets -shift_px..+shift_px
  int shift_step_px = 1;                   // step between compared offsets
  double match_threshold = 0.03;           // mean absolute difference (0..1 scale) for a match
  double global_normalisation_mean = 0.0;  // >0: scale each template to this mean; 0: off
  int patch_normalisation_radius_px = 0;   // >0: local contrast normalisation; 0: off
  bool panoramic = false;                  // the template spans 360 degrees: shifts wrap around

  bool IsValid(std::string* error) const;

  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("crop_left_px", crop_left_px, "first image column used", schema::Unit("px").NonNegative());
    v("crop_right_px", crop_right_px, "one past the last image column used; -1 for the width",
      schema::Unit("px").AtLeast(-1));
    v("crop_top_px", crop_top_px, "first image row used", schema::Unit("px").NonNegative());
    v("crop_bottom_px", crop_bottom_px, "one past the last image row used; -1 for the height",
      schema::Unit("px").AtLeast(-1));
    v("template_width_px", template_width_px, "template columns (block-mean down-sampling)",
      schema::Unit("px").Within(1, 4096));
    v("template_height_px", template_height_px, "template rows",
      schema::Unit("px").Within(1, 4096));
    v("shift_px", shift_px,
      "templates are compared at column offsets -shift_px..+shift_px (a panorama: every offset)",
      schema::Unit("px").NonNegative());
    v("shift_step_px", shift_step_px, "step between compared column offsets",
      schema::Unit("px").AtLeast(1));
    v("match_threshold", match_threshold,
      "largest mean absolute difference (intensities 0..1) that counts as a match",
      schema::Unit("").Within(0, 1));
    v("global_normalisation_mean", global_normalisation_mean,
      "scale each template to this mean intensity; 0 switches it off",
      schema::Unit("").Within(0, 1));
    v("patch_normalisation_radius_px", patch_normalisation_radius_px,
      "radius of the local contrast normalisation patch; 0 switches it off",
      schema::Unit("px").NonNegative());
    v("panoramic", panoramic, "the image spans 360 degrees: shifts wrap and give a heading change",
      schema::Any());
  }
};

// The best stored template for a view.
struct TemplateComparison {
  int32_t template_id = -1;        // -1 when nothing is stored
  double mean_difference = 1e300;  // on the 0..1 intensity scale
  int shift_px = 0;                // query column x matches template column x - shift_px
};

class ClassicCameraMatcher {
 public:
  struct State {
    std::vector<uint8_t> templates;  // template_count * bytes_per_template
    uint32_t template_count = 0;
  };

  // `options` must be valid; throws std::invalid_argument otherwise.
  explicit ClassicCameraMatcher(const ClassicCameraOptions& options);

  // Turns an image into a template, compares it with all stored ones and decides: a match, or a
  // new template (stored, with the next id). Fails on an image smaller than the crop.
  StatusOr<ViewDecision> Observe(const GrayImageView& image, double time_s);

  // Builds the template of an image (row-padded 8-bit layout) without storing it.
  StatusOr<std::vector<uint8_t>> MakeTemplate(const GrayImageView& image) const;
  // The stored template of the smallest difference to a template (from MakeTemplate), the lowest
  // id among equals, if that difference is at most `cutoff`; template_id -1 otherwise. Templates
  // whose exact lower bound (column sums) cannot beat the best so far are skipped, and with a
  // finite cutoff only templates whose column-sum total lies near the query's are visited at
  // all: the result is the full scan's. `hint`, a template likely to be close (Observe passes the
  // last frame's), is compared first so that fewer are visited; the result does not depend on it.
  TemplateComparison Compare(const std::vector<uint8_t>& query, int64_t hint = -1,
                             double cutoff = std::numeric_limits<double>::infinity()) const;
  // Templates Compare has compared in full (not skipped by the bound), since construction.
  uint64_t full_comparisons() const { return full_comparisons_; }
  // Templates whose lower bound Compare has evaluated, since construction.
  uint64_t bounds_checked() const { return bounds_checked_; }
  // Tests: use the portable SSE2 kernel even where AVX2 exists.
  void set_force_portable(bool portable) { force_portable_ = portable; }
  // The smallest mean difference over the shifts to every stored template, by id.
  std::vector<double> Differences(const std::vector<uint8_t>& query) const;
  // Stores a template (from MakeTemplate); returns its id.
  uint32_t Add(const std::vector<uint8_t>& query);

  uint32_t size() const { return state_.template_count; }
  size_t bytes_per_template() const { return bytes_per_template_; }
  const ClassicCameraOptions& options() const { return options_; }
  const State& state() const { return state_; }
  Status SetState(State state);

  // Shifted, masked copies of a query for the SIMD scan; opaque outside the implementation.
  struct PreparedQuery;

 private:
  PreparedQuery PrepareQuery(const std::vector<uint8_t>& query) const;
  template <typename Visit>
  void VisitTemplates(const PreparedQuery& prepared, Visit&& visit) const;
  // Appends template `id`'s column sums and files it in the total index.
  void Index(uint32_t id);
  // The ids (ascending) of every template that may be within `radius` of the query by the
  // total-over-overlap bound at some shift; false (and nothing) when that is about all of them.
  bool CandidatesWithin(const PreparedQuery& prepared, const std::vector<double>& scale,
                        double radius, std::vector<uint32_t>* out) const;

  // Per distinct overlap [first, last) of the shifts: template ids in buckets of their column-sum
  // total over it (bucket b holds totals in [b, b + 1) * bucket_width), each with its sums over
  // runs of the overlap's columns (a fixed number per id, when they fit 32 bits).
  struct TotalBuckets {
    struct Bucket {
      std::vector<uint32_t> ids;
      std::vector<int32_t> runs;
    };
    int first = 0, last = 0;
    int64_t bucket_width = 1;
    std::vector<Bucket> buckets;
  };
  static constexpr int64_t kTotalBuckets = 1024;

  ClassicCameraOptions options_;
  int row_stride_;  // template width rounded up to a multiple of 32 bytes
  size_t bytes_per_template_;
  std::vector<int> shifts_;
  State state_;
  // Per stored template: column sums (width) and their running sums (width + 1); rebuilt from
  // state_.
  std::vector<int32_t> column_sums_;
  std::vector<TotalBuckets> total_buckets_;  // rebuilt from state_
  std::vector<int> shift_overlap_;           // per shift: its entry in total_buckets_
  mutable uint64_t full_comparisons_ = 0;
  mutable uint64_t bounds_checked_ = 0;
  int64_t last_template_ = -1;  // Observe's last decision: the next Compare's hint
  bool force_portable_ = false;
};

}  // namespace ratslam::sensors

#endif  // RATSLAM_SENSORS_CLASSIC_CAMERA_MATCHER_H_
