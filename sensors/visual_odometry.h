// Odometry from a camera alone, as in the Wi-Fi RatSLAM paper's campus run (section IV-A): a
// constant forward speed, and the rotation between consecutive frames from how far the image's
// column intensity profile shifted (the scan-line approach of Milford and Wyeth 2008). A scene
// moving right in the image means the camera turned left (counter-clockwise).
#ifndef RATSLAM_SENSORS_VISUAL_ODOMETRY_H_
#define RATSLAM_SENSORS_VISUAL_ODOMETRY_H_

#include <optional>
#include <string>
#include <vector>

#include "common/schema.h"
#include "common/status.h"
#include "sensors/classic_camera_matcher.h"

namespace ratslam {

struct VisualOdometryOptions {
  bool enabled = false;            // replace the data set's odometry with visual odometry
  double speed_m_per_s = 1.0;      // the constant forward speed assumed
  double field_of_view_rad = 1.8;  // horizontal field of view of the camera
  int max_shift_px = 10;           // largest profile shift searched between frames
  int crop_top_px = 0;             // rows used for the profile: [top, bottom)
  int crop_bottom_px = -1;         // -1: image height

  bool IsValid(std::string* error) const;

  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("enabled", enabled, "replace the data set's odometry by visual odometry from its images",
      schema::Any());
    v("speed_m_per_s", speed_m_per_s, "constant forward speed assumed, m/s",
      schema::Unit("m/s").NonNegative());
    v("field_of_view_rad", field_of_view_rad, "horizontal field of view of the camera, rad",
      schema::Unit("rad").Positive().AtMost(2 * M_PI));
    v("max_shift_px", max_shift_px, "largest column shift searched between consecutive frames, px",
      schema::Unit("px").AtLeast(1));
    v("crop_top_px", crop_top_px, "first image row of the intensity profile",
      schema::Unit("px").NonNegative());
    v("crop_bottom_px", crop_bottom_px, "one past the last row of the profile; -1 for the height",
      schema::Unit("px").AtLeast(-1));
  }
};

class VisualOdometry {
 public:
  // `options` must be valid; throws std::invalid_argument otherwise.
  explicit VisualOdometry(const VisualOdometryOptions& options);

  // The rotation (rad, counter-clockwise) since the previous image; nullopt for the first image.
  // Fails on an image narrower than twice the shift range or with a different width.
  StatusOr<std::optional<double>> Rotation(const GrayImageView& image);

 private:
  VisualOdometryOptions options_;
  std::vector<double> previous_;
};

}  // namespace ratslam

#endif  // RATSLAM_SENSORS_VISUAL_ODOMETRY_H_
