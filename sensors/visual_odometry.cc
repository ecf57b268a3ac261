#include "sensors/visual_odometry.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace ratslam::sensors {

bool VisualOdometryOptions::IsValid(std::string* error) const {
  if (!schema::CheckFields(*this, error)) return false;
  auto span = [error](int first, int end, const char* first_key, const char* end_key) {
    if (end != -1 && end <= first) {
      if (error) *error = std::string(end_key) + ": must be -1 or greater than " + first_key;
      return false;
    }
    return true;
  };
  if (model != "constant_speed" && model != "openratslam") {
    if (error) *error = "model: must be constant_speed or openratslam, not '" + model + "'";
    return false;
  }
  return span(crop_top_px, crop_bottom_px, "crop_top_px", "crop_bottom_px") &&
         span(translation_left_px, translation_right_px, "translation_left_px",
              "translation_right_px") &&
         span(translation_top_px, translation_bottom_px, "translation_top_px",
              "translation_bottom_px") &&
         span(rotation_left_px, rotation_right_px, "rotation_left_px", "rotation_right_px") &&
         span(rotation_top_px, rotation_bottom_px, "rotation_top_px", "rotation_bottom_px");
}

namespace {

struct Region {
  int left, right, top, bottom;
};

// Column means (intensity 0..1) of `r` after resolving -1 ends; an error when it does not fit.
StatusOr<std::vector<double>> Profile(const GrayImageView& image, Region r, int max_shift,
                                      const char* name) {
  if (r.right < 0) r.right = image.width;
  if (r.bottom < 0) r.bottom = image.height;
  if (image.pixels == nullptr || r.right > image.width || r.bottom > image.height ||
      r.left >= r.right || r.top >= r.bottom) {
    return Status::Error(std::string("visual odometry: the ") + name + " region [" +
                         std::to_string(r.left) + ", " + std::to_string(r.right) + ") x [" +
                         std::to_string(r.top) + ", " + std::to_string(r.bottom) +
                         ") does not fit a " + std::to_string(image.width) + "x" +
                         std::to_string(image.height) + " image");
  }
  if (r.right - r.left <= max_shift) {
    return Status::Error(std::string("visual odometry: the ") + name +
                         " region is not wider than max_shift_px");
  }
  std::vector<double> profile(static_cast<size_t>(r.right - r.left), 0.0);
  for (int y = r.top; y < r.bottom; ++y) {
    const uint8_t* row = image.pixels + static_cast<size_t>(y) * image.stride_bytes;
    for (int x = r.left; x < r.right; ++x) profile[static_cast<size_t>(x - r.left)] += row[x];
  }
  const double scale = 1.0 / (255.0 * (r.bottom - r.top));
  for (double& v : profile) v *= scale;
  return profile;
}

// OpenRatSLAM's shift search: (best shift, its mean absolute difference).
std::pair<int, double> BestShift(const std::vector<double>& p, const std::vector<double>& q,
                                 int max_shift) {
  const int w = static_cast<int>(p.size());
  auto mean = [&](int o, bool right) {
    double sum = 0.0;
    for (int k = 0; k < w - o; ++k) {
      sum += right ? std::abs(p[static_cast<size_t>(k + o)] - q[static_cast<size_t>(k)])
                   : std::abs(p[static_cast<size_t>(k)] - q[static_cast<size_t>(k + o)]);
    }
    return sum / (w - o);
  };
  int best_shift = 0;
  double best = std::numeric_limits<double>::infinity();
  for (int o = 0; o <= max_shift; ++o) {  // 0, then -1 .. -max
    const double d = mean(o, false);
    if (d < best) {
      best = d;
      best_shift = -o;
    }
  }
  for (int o = 1; o <= max_shift; ++o) {  // then +1 .. +max
    const double d = mean(o, true);
    if (d < best) {
      best = d;
      best_shift = o;
    }
  }
  return {best_shift, best};
}

}  // namespace

OpenRatslamVisualOdometry::OpenRatslamVisualOdometry(const VisualOdometryOptions& options)
    : options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("VisualOdometryOptions: " + error);
}

StatusOr<std::optional<VisualVelocities>> OpenRatslamVisualOdometry::Step(
    const GrayImageView& image) {
  const VisualOdometryOptions& o = options_;
  StatusOr<std::vector<double>> translation =
      Profile(image,
              {o.translation_left_px, o.translation_right_px, o.translation_top_px,
               o.translation_bottom_px},
              o.max_shift_px, "translation");
  if (!translation.ok()) return translation.status();
  StatusOr<std::vector<double>> rotation = Profile(
      image, {o.rotation_left_px, o.rotation_right_px, o.rotation_top_px, o.rotation_bottom_px},
      o.max_shift_px, "rotation");
  if (!rotation.ok()) return rotation.status();
  std::optional<VisualVelocities> out;
  if (!previous_rotation_.empty()) {
    if (image.width != width_ || image.height != height_) {
      return Status::Error("visual odometry: image size changed between frames");
    }
    const double diff = BestShift(*translation, previous_translation_, o.max_shift_px).second;
    const int shift = BestShift(*rotation, previous_rotation_, o.max_shift_px).first;
    out = VisualVelocities{std::min(o.translation_scaling * diff, o.max_speed_m_per_s),
                           shift * (o.field_of_view_rad / image.width) * o.camera_hz};
  }
  width_ = image.width;
  height_ = image.height;
  previous_translation_ = std::move(translation).value();
  previous_rotation_ = std::move(rotation).value();
  return out;
}

VisualOdometry::VisualOdometry(const VisualOdometryOptions& options) : options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("VisualOdometryOptions: " + error);
}

StatusOr<std::optional<double>> VisualOdometry::Rotation(const GrayImageView& image) {
  const int bottom = options_.crop_bottom_px < 0 ? image.height : options_.crop_bottom_px;
  if (image.pixels == nullptr || bottom > image.height || options_.crop_top_px >= bottom) {
    return Status::Error("visual odometry: image smaller than the profile rows");
  }
  if (image.width <= 2 * options_.max_shift_px) {
    return Status::Error("visual odometry: image narrower than twice max_shift_px");
  }
  // Column means over the profile rows.
  std::vector<double> profile(image.width, 0.0);
  for (int y = options_.crop_top_px; y < bottom; ++y) {
    const uint8_t* row = image.pixels + static_cast<size_t>(y) * image.stride_bytes;
    for (int x = 0; x < image.width; ++x) profile[x] += row[x];
  }
  for (double& v : profile) v /= (bottom - options_.crop_top_px);
  std::optional<double> rotation;
  if (!previous_.empty()) {
    if (previous_.size() != profile.size()) {
      return Status::Error("visual odometry: image width changed between frames");
    }
    // Shift s: the current column x shows what the previous frame had at x - s.
    double best = std::numeric_limits<double>::infinity();
    int best_shift = 0;
    const int w = image.width;
    for (int s = -options_.max_shift_px; s <= options_.max_shift_px; ++s) {
      double sum = 0.0;
      int n = 0;
      for (int x = std::max(0, s); x < std::min(w, w + s); ++x) {
        sum += std::abs(profile[x] - previous_[x - s]);
        ++n;
      }
      const double mean = sum / n;
      if (mean < best) {
        best = mean;
        best_shift = s;
      }
    }
    rotation = best_shift * options_.field_of_view_rad / image.width;
  }
  previous_ = std::move(profile);
  return rotation;
}

}  // namespace ratslam::sensors
