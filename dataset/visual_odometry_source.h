// Replaces a data set's odometry by visual odometry computed from its images (constant speed,
// rotation from consecutive frames; see sensors/visual_odometry.h).
#ifndef RATSLAM_DATASET_VISUAL_ODOMETRY_SOURCE_H_
#define RATSLAM_DATASET_VISUAL_ODOMETRY_SOURCE_H_

#include "common/status.h"
#include "dataset/dataset.h"
#include "dataset/image_loader.h"
#include "sensors/visual_odometry.h"

namespace ratslam::dataset {

// One odometry row per image (the first at rest). Errors name images.csv's line.
Status ReplaceOdometryWithVisual(Dataset* dataset, ImageLoader* images,
                                 const sensors::VisualOdometryOptions& options);

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_VISUAL_ODOMETRY_SOURCE_H_
