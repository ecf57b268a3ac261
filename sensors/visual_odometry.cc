#include "sensors/visual_odometry.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace ratslam {

bool VisualOdometryOptions::IsValid(std::string* error) const {
  if (!schema::CheckFields(*this, error)) return false;
  if (crop_bottom_px != -1 && crop_bottom_px <= crop_top_px) {
    if (error) *error = "crop_bottom_px: must be -1 or greater than crop_top_px";
    return false;
  }
  return true;
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

}  // namespace ratslam
