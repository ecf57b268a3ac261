// Odometry from a camera alone, two models:
// - constant_speed, as in the Wi-Fi RatSLAM paper's campus run (section IV-A): a constant forward
//   speed, and the rotation between consecutive frames from how far the image's column intensity
//   profile shifted (the scan-line approach of Milford and Wyeth 2008).
// - openratslam, OpenRatSLAM's visual odometry node (what its St Lucia data set runs on), from
//   the facts in ../shared/reference/openratslam-facts.md, section 4.2: one region's profile
//   shift gives the rotation, scaled by the camera rate; another region's smallest mean profile
//   difference gives the speed, scaled and clipped.
// A scene moving right in the image means the camera turned left (counter-clockwise).
#ifndef RATSLAM_SENSORS_VISUAL_ODOMETRY_H_
#define RATSLAM_SENSORS_VISUAL_ODOMETRY_H_

#include <optional>
#include <string>
#include <vector>

#include "common/schema.h"
#include "common/status.h"
#include "sensors/classic_camera_matcher.h"

namespace ratslam::sensors {

struct VisualOdometryOptions {
  bool enabled = false;                  // replace the data set's odometry with visual odometry
  double speed_m_per_s = 1.0;            // the constant forward speed assumed
  double field_of_view_rad = 1.8;        // horizontal field of view of the camera
  int max_shift_px = 10;                 // largest profile shift searched between frames
  int crop_top_px = 0;                   // rows used for the profile: [top, bottom)
  int crop_bottom_px = -1;               // -1: image height
  std::string model = "constant_speed";  // or "openratslam"
  // openratslam: the translation and rotation regions, [left, right) x [top, bottom) in pixels,
  // -1 for the image's width or height (OpenRatSLAM's vtrans_image_* and vrot_image_* keys).
  int translation_left_px = 0, translation_right_px = -1;
  int translation_top_px = 0, translation_bottom_px = -1;
  int rotation_left_px = 0, rotation_right_px = -1;
  int rotation_top_px = 0, rotation_bottom_px = -1;
  double camera_hz = 10.0;           // per-frame rotation times this is the turn rate
  double translation_scaling = 100;  // speed per unit mean intensity difference (0..1)
  double max_speed_m_per_s = 20.0;   // the speed's upper clip

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
    v("model", model,
      "constant_speed (speed_m_per_s and a profile shift for the rotation) or openratslam "
      "(OpenRatSLAM's visual odometry: the keys below)",
      schema::Any());
    v("translation_left_px", translation_left_px, "openratslam: speed region, first column",
      schema::Unit("px").NonNegative());
    v("translation_right_px", translation_right_px,
      "openratslam: speed region, one past the last column; -1 for the width",
      schema::Unit("px").AtLeast(-1));
    v("translation_top_px", translation_top_px, "openratslam: speed region, first row",
      schema::Unit("px").NonNegative());
    v("translation_bottom_px", translation_bottom_px,
      "openratslam: speed region, one past the last row; -1 for the height",
      schema::Unit("px").AtLeast(-1));
    v("rotation_left_px", rotation_left_px, "openratslam: rotation region, first column",
      schema::Unit("px").NonNegative());
    v("rotation_right_px", rotation_right_px,
      "openratslam: rotation region, one past the last column; -1 for the width",
      schema::Unit("px").AtLeast(-1));
    v("rotation_top_px", rotation_top_px, "openratslam: rotation region, first row",
      schema::Unit("px").NonNegative());
    v("rotation_bottom_px", rotation_bottom_px,
      "openratslam: rotation region, one past the last row; -1 for the height",
      schema::Unit("px").AtLeast(-1));
    v("camera_hz", camera_hz,
      "openratslam: frame rate assumed; the per-frame rotation times this is the turn rate",
      schema::Unit("Hz").Positive());
    v("translation_scaling", translation_scaling,
      "openratslam: speed (m/s) per unit of the smallest mean profile difference (0..1)",
      schema::Unit("m/s").NonNegative());
    v("max_speed_m_per_s", max_speed_m_per_s, "openratslam: upper clip of the speed",
      schema::Unit("m/s").NonNegative());
  }
};

// Velocities that hold from the previous frame to this one.
struct VisualVelocities {
  double forward_m_per_s = 0.0;
  double turn_rate_rad_per_s = 0.0;
};

// The openratslam model. Search order and ties as OpenRatSLAM: shifts 0, -1 .. -max, +1 .. +max,
// the first strict minimum wins.
class OpenRatslamVisualOdometry {
 public:
  // `options` must be valid; throws std::invalid_argument otherwise.
  explicit OpenRatslamVisualOdometry(const VisualOdometryOptions& options);

  // Velocities since the previous image; nullopt for the first image (OpenRatSLAM's first
  // output compares with an all-zero profile and is never integrated). Fails when a region does
  // not fit the image or is not wider than max_shift_px, or when the image size changes.
  StatusOr<std::optional<VisualVelocities>> Step(const GrayImageView& image);

 private:
  VisualOdometryOptions options_;
  std::vector<double> previous_translation_, previous_rotation_;
  int width_ = 0, height_ = 0;
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

}  // namespace ratslam::sensors

#endif  // RATSLAM_SENSORS_VISUAL_ODOMETRY_H_
