#include "io/visual_model_file.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <system_error>

#include "common/text_file.h"

namespace ratslam::io {

StatusOr<std::vector<std::string>> ListImages(const std::string& folder) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) return Status::Error(folder + ": not a folder of images");
  std::vector<std::string> images;
  for (auto it = fs::recursive_directory_iterator(folder, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (!it->is_regular_file(ec)) continue;
    std::string ext = it->path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    if (ext == ".jpg" || ext == ".jpeg" || ext == ".png" || ext == ".pgm") {
      images.push_back(it->path().string());
    }
  }
  if (ec) return Status::Error(folder + ": " + ec.message());
  std::sort(images.begin(), images.end());
  return images;
}

StatusOr<fabmap::TrainedVisualModel> LoadOrTrainVisualModel(
    const fabmap::VisualModelOptions& options, const fabmap::FeatureOptions& features,
    const fabmap::VocabularyOptions& vocabulary, const fabmap::ChowLiuOptions& chow_liu,
    ImageLoader& loader, const std::function<void(size_t, size_t)>& progress) {
  if (!options.file.empty()) {
    StatusOr<std::string> bytes = ReadRegularFile(options.file, "visual model", size_t{1} << 34);
    if (!bytes.ok()) return bytes.status();
    return fabmap::DecodeVisualModel(*bytes, options.file);
  }
  if (options.training_images.empty()) {
    return Status::Error("[visual_model] needs file or training_images");
  }
  auto all = ListImages(options.training_images);
  if (!all.ok()) return all.status();
  std::vector<std::string> chosen;
  for (size_t i = 0; i < all->size(); i += options.training_image_step) chosen.push_back((*all)[i]);
  return fabmap::TrainVisualModel(chosen, features, vocabulary, chow_liu, loader, progress);
}

StatusOr<std::shared_ptr<const fusion::FabmapResources>> LoadFabmapResources(
    const fusion::FrontEndSettings& settings, const dataset::Dataset& dataset,
    ImageLoader& images) {
  const fusion::FabmapSettings& f = settings.fabmap;
  std::optional<fabmap::TrainedVisualModel> visual;
  if (fabmap::UsesVision(f.localiser.localiser.mode)) {
    std::string error;
    if (!f.IsValid(&error)) return Status::Error("FABMAP settings: " + error);
    auto model = LoadOrTrainVisualModel(f.visual_model, f.features, f.vocabulary,
                                        f.localiser.chow_liu, images);
    if (!model.ok()) {
      return model.status().WithContext("FABMAP mode " +
                                        fabmap::ToString(f.localiser.localiser.mode));
    }
    visual = *std::move(model);
  }
  return fusion::PrepareFabmapResources(settings, dataset, std::move(visual));
}

}  // namespace ratslam::io
