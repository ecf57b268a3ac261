// The visual model's files: a saved model (fabmap::EncodeVisualModel's bytes) or a folder of
// training images. FABMAP itself reads no file; sessions load the model here and hand it to
// PrepareFabmapResources.
#ifndef RATSLAM_IO_VISUAL_MODEL_FILE_H_
#define RATSLAM_IO_VISUAL_MODEL_FILE_H_

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/status.h"
#include "dataset/image_loader.h"
#include "fusion/fabmap/visual_model.h"
#include "fusion/front_end.h"

namespace ratslam::io {

// Sorted image files (jpg, jpeg, png, pgm) under `folder`, recursively.
StatusOr<std::vector<std::string>> ListImages(const std::string& folder);

// The model `options` names: read from `file`, or trained on every training_image_step-th image
// under `training_images`; `progress` (optional) gets (done, total) per training image.
StatusOr<fabmap::TrainedVisualModel> LoadOrTrainVisualModel(
    const fabmap::VisualModelOptions& options, const fabmap::FeatureOptions& features,
    const fabmap::VocabularyOptions& vocabulary, const fabmap::ChowLiuOptions& chow_liu,
    ImageLoader& loader, const std::function<void(size_t, size_t)>& progress = nullptr);

// PrepareFabmapResources with the visual model loaded (or trained) first when the mode uses
// vision: what a replay of the FABMAP front end needs.
StatusOr<std::shared_ptr<const fusion::FabmapResources>> LoadFabmapResources(
    const fusion::FrontEndSettings& settings, const dataset::Dataset& dataset, ImageLoader& images);

}  // namespace ratslam::io

#endif  // RATSLAM_IO_VISUAL_MODEL_FILE_H_
