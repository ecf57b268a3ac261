// The offline part of visual FABMAP (the fusion paper's section 2 and 5.1): a vocabulary, a
// Chow-Liu tree and unknown-world samples, all learnt from training images, and saved together
// in one file so that evaluations and replays reuse them.
#ifndef RATSLAM_FUSION_FABMAP_VISUAL_MODEL_H_
#define RATSLAM_FUSION_FABMAP_VISUAL_MODEL_H_

#include <functional>
#include <string>
#include <vector>

#include "common/gray_image.h"
#include "common/schema.h"
#include "common/status.h"
#include "fusion/fabmap/localiser.h"
#include "fusion/fabmap/vocabulary.h"

namespace ratslam::fabmap {

struct VisualModelOptions {
  std::string file;             // a saved visual model; empty: train from training_images
  std::string training_images;  // folder searched recursively for images (jpg, png, pgm)
  int training_image_step = 5;  // every n-th training image is used

  bool IsValid(std::string* error) const;
  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("file", file, "saved visual model (vocabulary, tree, samples); empty: train one",
      schema::Any());
    v("training_images", training_images,
      "folder of training images (searched recursively), used when file is empty", schema::Any());
    v("training_image_step", training_image_step, "every n-th training image is used",
      schema::Unit("images").AtLeast(1));
  }
};

struct TrainedVisualModel {
  FeatureOptions features;
  Vocabulary vocabulary;
  VisualModel model;  // tree and unknown-world samples (the training observations)
};

// Trains on `images` (read through `loader`); `progress` (optional) gets (done, total) per
// image. Loading a saved model or listing a folder is io/visual_model_file.h's job.
StatusOr<TrainedVisualModel> TrainVisualModel(const std::vector<std::string>& images,
                                              const FeatureOptions& features,
                                              const VocabularyOptions& vocabulary,
                                              const ChowLiuOptions& chow_liu, ImageLoader& loader,
                                              const std::function<void(size_t, size_t)>& progress);

// Visual words of one image.
StatusOr<Observation> ImageWords(const TrainedVisualModel& model, const GrayImage& image);

std::string EncodeVisualModel(const TrainedVisualModel& model);
StatusOr<TrainedVisualModel> DecodeVisualModel(const std::string& bytes, const std::string& source);

}  // namespace ratslam::fabmap

#endif  // RATSLAM_FUSION_FABMAP_VISUAL_MODEL_H_
