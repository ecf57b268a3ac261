#include "sensors/dataset/visual_odometry_source.h"

namespace ratslam {

Status ReplaceOdometryWithVisual(Dataset* dataset, ImageLoader* images,
                                 const VisualOdometryOptions& options) {
  if (dataset->images.empty()) {
    return Status::Error(dataset->name + ": visual odometry needs images; the data set has none");
  }
  VisualOdometry vo(options);
  std::vector<OdometryRow> rows;
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

}  // namespace ratslam
