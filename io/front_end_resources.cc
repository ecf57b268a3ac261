#include "io/front_end_resources.h"

#include <filesystem>

#include "dataset/descriptor_file.h"
#include "io/visual_model_file.h"

namespace ratslam::io {

namespace fs = std::filesystem;

StatusOr<std::shared_ptr<const fusion::DescriptorTable>> LoadDescriptorTable(
    const fusion::DescriptorOptions& options, const std::vector<std::string>& data_paths,
    const dataset::Dataset& dataset) {
  if (data_paths.empty()) return Status::Error("descriptors: no data set given");
  const fs::path file(options.file);
  if (file.is_absolute() && data_paths.size() > 1) {
    return Status::Error("descriptors.file is absolute (" + options.file + "), but the run has " +
                         std::to_string(data_paths.size()) +
                         " sessions: give a name each session's folder holds");
  }
  const std::vector<double>& starts = dataset.session_start_times_s;
  dataset::DescriptorMatrix joined;
  std::string names;
  size_t image = 0;
  for (size_t s = 0; s < data_paths.size(); ++s) {
    std::error_code ec;
    const fs::path data(data_paths[s]);
    const fs::path folder = fs::is_directory(data, ec) ? data : data.parent_path();
    const std::string path = file.is_absolute() ? file.string() : (folder / file).string();
    StatusOr<dataset::DescriptorMatrix> m = dataset::ReadDescriptorFile(path);
    if (!m.ok()) return m.status();
    // This session's images: those before the next session's start.
    size_t end = dataset.images.size();
    if (data_paths.size() > 1 && s + 1 < starts.size()) {
      end = image;
      while (end < dataset.images.size() && dataset.images[end].time_s < starts[s + 1]) ++end;
    }
    if (m->rows != end - image) {
      return Status::Error(path + ": " + std::to_string(m->rows) + " descriptors, but " +
                           (data_paths.size() > 1 ? "session " + data_paths[s] : "the data set") +
                           " has " + std::to_string(end - image) +
                           " camera images (one descriptor per image, in image order)");
    }
    if (s > 0 && m->cols != joined.cols) {
      return Status::Error(path + ": descriptors of " + std::to_string(m->cols) +
                           " dimensions, but the first session's have " +
                           std::to_string(joined.cols));
    }
    joined.cols = m->cols;
    joined.rows += m->rows;
    joined.values.insert(joined.values.end(), m->values.begin(), m->values.end());
    names += (s ? ", " : "") + path;
    image = end;
  }
  return fusion::DescriptorTable::Make(joined, dataset, names);
}

StatusOr<fusion::FrontEndResources> LoadFrontEndResources(
    const fusion::FrontEndSettings& settings, const std::vector<std::string>& data_paths,
    const dataset::Dataset& dataset, ImageLoader& images) {
  fusion::FrontEndResources resources;
  if (settings.front_end.kind == fusion::FrontEndKind::kFabmap) {
    auto prepared = LoadFabmapResources(settings, dataset, images);
    if (!prepared.ok()) return prepared.status().WithContext("FABMAP front end");
    resources.fabmap = *prepared;
  } else if (settings.front_end.kind == fusion::FrontEndKind::kDescriptors) {
    auto table = LoadDescriptorTable(settings.descriptors, data_paths, dataset);
    if (!table.ok()) return table.status().WithContext("descriptor front end");
    resources.descriptors = *table;
  }
  return resources;
}

}  // namespace ratslam::io
