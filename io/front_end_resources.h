// What a replay's front end is built from beyond its options, read from files: FABMAP's models
// (visual_model_file.h) and a data set's descriptor files.
#ifndef RATSLAM_IO_FRONT_END_RESOURCES_H_
#define RATSLAM_IO_FRONT_END_RESOURCES_H_

#include <memory>
#include <string>
#include <vector>

#include "common/status.h"
#include "dataset/image_loader.h"
#include "fusion/front_end.h"

namespace ratslam::io {

// The descriptors of `dataset`, loaded from the sessions `data_paths` (as given to
// LoadSessions) by DescriptorOptions::file: a relative name inside each session's folder (a
// folder data set) or beside its file (bag, video, log), one file per session, each with one
// row per image of its session; an absolute path for a single session.
StatusOr<std::shared_ptr<const fusion::DescriptorTable>> LoadDescriptorTable(
    const fusion::DescriptorOptions& options, const std::vector<std::string>& data_paths,
    const dataset::Dataset& dataset);

// Every resource the configured front end needs (none for most kinds; the custom factory is
// the caller's to add).
StatusOr<fusion::FrontEndResources> LoadFrontEndResources(
    const fusion::FrontEndSettings& settings, const std::vector<std::string>& data_paths,
    const dataset::Dataset& dataset, ImageLoader& images);

}  // namespace ratslam::io

#endif  // RATSLAM_IO_FRONT_END_RESOURCES_H_
