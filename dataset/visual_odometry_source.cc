#include "dataset/visual_odometry_source.h"

namespace ratslam::dataset {

Status ReplaceOdometryWithVisual(Dataset* dataset, ImageLoader* images,
                                 const sensors::VisualOdometryOptions& options) {
  if (dataset->images.empty()) {
    return Status::Error(dataset->name + ": visual odometry needs images; the data set has none");
  }
  std::vector<OdometryRow> rows;
  if (options.model == "openratslam") {
    // OpenRatSLAM publishes velocities per frame, stamped with the frame; they hold from the
    // previous frame, as an odometry row's do.
    sensors::OpenRatslamVisualOdometry vo(options);
    for (const ImageRow& row : dataset->images) {
      StatusOr<GrayImage> image = images->Load(dataset->ImagePath(row));
      if (!image.ok()) return image.status().WithContext("image " + std::to_string(row.line));
      StatusOr<std::optional<sensors::VisualVelocities>> v =
          vo.Step({image->width, image->height, image->width, image->pixels.data()});
      if (!v.ok()) return v.status().WithContext(dataset->ImagePath(row));
      if (rows.empty()) {
        rows.push_back({row.time_s, 0.0, 0.0});
      } else if (v.value() && row.time_s > rows.back().time_s) {
        rows.push_back({row.time_s, v.value()->forward_m_per_s, v.value()->turn_rate_rad_per_s});
      }
    }
    dataset->odometry = std::move(rows);
    return Status::Ok();
  }
  sensors::VisualOdometry vo(options);
  for (const ImageRow& row : dataset->images) {
    StatusOr<GrayImage> image = images->Load(dataset->ImagePath(row));
    if (!image.ok()) return image.status().WithContext("images.csv:" + std::to_string(row.line));
    StatusOr<std::optional<double>> rotation =
        vo.Rotation({image->width, image->height, image->width, image->pixels.data()});
    if (!rotation.ok()) return rotation.status().WithContext(row.file);
    if (!rotation.value() || rows.empty() || row.time_s <= rows.back().time_s) {
      if (rows.empty()) rows.push_back({row.time_s, 0.0, 0.0});
      continue;
    }
    const double dt = row.time_s - rows.back().time_s;
    rows.push_back({row.time_s, options.speed_m_per_s, *rotation.value() / dt});
  }
  dataset->odometry = std::move(rows);
  return Status::Ok();
}

}  // namespace ratslam::dataset
