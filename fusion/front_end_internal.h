// What the front ends share, for their own .cc files only (not installed).
#ifndef RATSLAM_FUSION_FRONT_END_INTERNAL_H_
#define RATSLAM_FUSION_FRONT_END_INTERNAL_H_

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "fusion/front_end.h"

namespace ratslam::fusion::front_end_internal {

template <typename T>
bool AllFinite(const std::vector<T>& values) {
  return std::all_of(values.begin(), values.end(), [](T v) { return std::isfinite(v); });
}
inline bool FiniteOrAbsent(const std::optional<double>& v) { return !v || std::isfinite(*v); }

inline sensors::GrayImageView ViewOf(const GrayImage& image) {
  return {image.width, image.height, image.width, image.pixels.data()};
}

// The recency rule of eqs. 10-11, shared by the fused and FABMAP front ends: a match to template
// `best` of `count` counts only when it is at least `recency_templates` templates and
// `recency_s` seconds old (made at `created_s`, now `now_s`).
// Templates below `settled` come from a saved map (FrontEnd::SettleForLocalisation): always old.
inline bool OldEnough(int64_t count, int64_t best, double now_s, double created_s,
                      int recency_templates, double recency_s, int64_t settled = 0) {
  return best < settled || (count - best >= recency_templates && now_s - created_s >= recency_s);
}

std::unique_ptr<FrontEnd> MakeClassicCameraFrontEnd(const sensors::ClassicCameraOptions& options);
std::unique_ptr<FrontEnd> MakeFusedFrontEnd(const FusedOptions& options,
                                            const sensors::KernelCameraOptions& camera,
                                            const sensors::WifiMatcherOptions& wifi,
                                            const FloorOptions& floors);
std::unique_ptr<FrontEnd> MakeNoViewFrontEnd();
std::unique_ptr<FrontEnd> MakeDescriptorFrontEnd(const DescriptorOptions& options,
                                                 std::shared_ptr<const DescriptorTable> table);
std::unique_ptr<FrontEnd> MakeFabmapFrontEnd(const FabmapSettings& settings,
                                             const FloorOptions& floors,
                                             std::shared_ptr<const FabmapResources> resources);

// Sequence recognition in front of `inner` ([sequence] recognise_views; fusion/
// sequence_recognition.cc): a camera frame whose sequence is recognised re-uses the template of
// the frame it matched, a blank frame (no contrast) gives no view, and `inner` decides every
// other frame.
std::unique_ptr<FrontEnd> MakeSequenceRecognition(std::unique_ptr<FrontEnd> inner,
                                                  const sensors::SequenceMatcherOptions& options);

}  // namespace ratslam::fusion::front_end_internal

#endif  // RATSLAM_FUSION_FRONT_END_INTERNAL_H_
