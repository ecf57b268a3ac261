// The camera templates of the Wi-Fi RatSLAM paper (section III-C, eq. 7): the grey image
// block-averaged to 12x9 and compared by a Gaussian kernel over all pixels,
//   c(j) = prod_x exp(-(p_x - p_x^j)^2 / (2 sigma^2)) = exp(-sum_x (p_x - p_x^j)^2 / (2 sigma^2)).
// Intensity scale: pixels are grey / 255 (0..1), minus the template's mean when subtract_mean is
// on (a global brightness change then costs nothing). With the paper's sigma = 2 and threshold
// t = 0.96, a match needs sum (dp)^2 <= -2 sigma^2 ln t = 0.327, an RMS difference of 0.055
// (14 grey levels) over 108 pixels: tolerant of noise and small shifts, strict across places.
#ifndef RATSLAM_SENSORS_KERNEL_CAMERA_MATCHER_H_
#define RATSLAM_SENSORS_KERNEL_CAMERA_MATCHER_H_

#include <cstdint>
#include <string>
#include <vector>

#include "common/schema.h"
#include "common/status.h"
#include "sensors/classic_camera_matcher.h"

namespace ratslam::sensors {

struct KernelCameraOptions {
  int template_width_px = 12;     // template columns
  int template_height_px = 9;     // template rows
  double kernel_sigma = 2.0;      // sigma_camera of eq. 7, on the 0..1 intensity scale
  double match_threshold = 0.96;  // t_camera: smallest c(j) that is a match
  bool subtract_mean = true;      // remove each template's mean intensity

  bool IsValid(std::string* error) const;

  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("template_width_px", template_width_px, "template columns (paper: 12)",
      schema::Unit("px").Within(1, 1024));
    v("template_height_px", template_height_px, "template rows (paper: 9)",
      schema::Unit("px").Within(1, 1024));
    v("kernel_sigma", kernel_sigma,
      "sigma_camera of eq. 7 on the 0..1 intensity scale (paper: 2.0)",
      schema::Unit("").Positive());
    v("match_threshold", match_threshold,
      "t_camera: smallest similarity c(j) that is a match (paper: 0.96)",
      schema::Unit("").Within(0, 1));
    v("subtract_mean", subtract_mean, "remove each template's mean intensity before comparing",
      schema::Any());
  }
};

struct KernelCameraMatch {
  int32_t id = -1;          // -1: nothing stored
  double similarity = 0.0;  // c(b) of eq. 7
};

class KernelCameraMatcher {
 public:
  // `options` must be valid; throws std::invalid_argument otherwise.
  explicit KernelCameraMatcher(const KernelCameraOptions& options);

  // The template of an image: block means, scaled to 0..1, optionally mean-subtracted.
  StatusOr<std::vector<float>> MakeTemplate(const GrayImageView& image) const;
  double Similarity(const std::vector<float>& a, const std::vector<float>& b) const;
  // Eq. 8; with `allowed` (one flag per template), the best among those whose flag is set.
  KernelCameraMatch Best(const std::vector<float>& query,
                         const std::vector<uint8_t>* allowed = nullptr) const;
  // Stores a template (an empty one never matches); returns its id.
  uint32_t Add(const std::vector<float>& t);
  uint32_t size() const { return static_cast<uint32_t>(templates_.size()); }
  const KernelCameraOptions& options() const { return options_; }
  const std::vector<std::vector<float>>& templates() const { return templates_; }
  Status SetTemplates(std::vector<std::vector<float>> templates);

 private:
  KernelCameraOptions options_;
  std::vector<std::vector<float>> templates_;
};

}  // namespace ratslam::sensors

#endif  // RATSLAM_SENSORS_KERNEL_CAMERA_MATCHER_H_
