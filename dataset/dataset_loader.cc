#include "dataset/dataset_loader.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "common/file_util.h"
#include "common/text_file.h"
#include "dataset/msft_log.h"
#include "dataset/rosbag2.h"
#include "dataset/video.h"

namespace ratslam::dataset {
namespace fs = std::filesystem;

StatusOr<DatasetFormat> DetectDatasetFormat(const std::string& path) {
  if (IsDirectory(path)) {
    if (PathExists(fs::path(path) / "manifest.toml")) return DatasetFormat::kReplayFolder;
    if (LooksLikeRos2Bag(path)) return DatasetFormat::kRos2Bag;
    return Status::Error(path +
                         ": a folder without manifest.toml (a replay data set) or metadata.yaml (a "
                         "ROS 2 bag) is not a data set");
  }
  if (!PathExists(path)) return Status::Error(path + ": no such file or folder");
  // Only regular files: a FIFO would block the open for ever, a device never end.
  std::ifstream in;
  RATSLAM_RETURN_IF_ERROR(OpenRegularFile(path, "data set", &in));
  if (LooksLikeRosbag(path)) return DatasetFormat::kRosBag;
  if (LooksLikeRos2Bag(path)) return DatasetFormat::kRos2Bag;
  if (LooksLikeVideo(path)) return DatasetFormat::kVideo;
  // The format is told by a bounded prefix: 200 lines of at most 64 KiB (a file without line
  // breaks, however large, costs 64 KiB here).
  std::string line;
  for (int i = 0; i < 200 && ReadLine(in, &line, size_t{1} << 16) == LineResult::kLine; ++i) {
    if (line.empty() || line[0] == '%') continue;
    if (line[0] == '#') {
      if (line.find("SiteID:") != std::string::npos ||
          line.find("startTime:") != std::string::npos) {
        return DatasetFormat::kMicrosoftLog;
      }
      continue;
    }
    if (line.find("\tTYPE_") != std::string::npos) return DatasetFormat::kMicrosoftLog;
    for (const char* type : {"WIFI;", "ACCE;", "GYRO;", "MAGN;", "AHRS;", "POSI;", "PRES;"}) {
      if (line.rfind(type, 0) == 0) return DatasetFormat::kIpinLog;
    }
  }
  return Status::Error(
      path +
      ": unknown data-set format (expected a replay folder, a ROS 1 or ROS 2 bag, an IPIN log or "
      "a Microsoft walk)");
}

namespace {
StatusOr<Dataset> Read(const std::string& path, DatasetFormat format,
                       const PhoneLogOptions& phone_options, const BagTopics& bag,
                       const VideoOptions& video, PhoneLogReport* report) {
  switch (format) {
    case DatasetFormat::kReplayFolder:
      return ReadDataset(path);
    case DatasetFormat::kIpinLog:
      return ReadIpinLog(path, phone_options, report);
    case DatasetFormat::kMicrosoftLog:
      return ReadMicrosoftLog(path, phone_options, report);
    case DatasetFormat::kRosBag:
      return ReadRosbag(path, bag);
    case DatasetFormat::kRos2Bag:
      return ReadRos2Bag(path, bag);
    case DatasetFormat::kVideo:
      return ReadVideo(path, video);
  }
  return Status::Error(path + ": unsupported format");
}
}  // namespace

StatusOr<Dataset> LoadDataset(const std::string& path, const PhoneLogOptions& phone_options,
                              const BagTopics& bag, const VideoOptions& video) {
  StatusOr<DatasetFormat> format = DetectDatasetFormat(path);
  if (!format.ok()) return format.status();
  PhoneLogReport report;
  StatusOr<Dataset> d = Read(path, *format, phone_options, bag, video, &report);
  if (d.ok()) d->skipped_malformed_lines = report.skipped_malformed;
  return d;
}

StatusOr<Dataset> LoadSessions(const std::vector<std::string>& paths,
                               const PhoneLogOptions& phone_options, double gap_s,
                               const BagTopics& bag, const VideoOptions& video) {
  if (paths.empty()) return Status::Error("no data set given");
  if (paths.size() == 1) {
    StatusOr<Dataset> d = LoadDataset(paths[0], phone_options, bag, video);
    // A replay folder that joined several sessions (ratslam import of several logs) keeps them.
    if (d.ok() && d->session_start_times_s.size() <= 1) {
      d->session_start_times_s = {d->odometry.empty() ? 0.0 : d->odometry.front().time_s};
    }
    return d;
  }
  Dataset joined;
  PhoneLogOptions options = phone_options;
  double end_of_previous = -std::numeric_limits<double>::infinity();
  for (const std::string& path : paths) {
    PhoneLogReport report;
    StatusOr<DatasetFormat> format = DetectDatasetFormat(path);
    if (!format.ok()) return format.status();
    StatusOr<Dataset> d = Read(path, *format, options, bag, video, &report);
    if (!d.ok()) return d.status();
    joined.skipped_malformed_lines += report.skipped_malformed;
    if (format.value() == DatasetFormat::kIpinLog && !options.reference) {
      options.reference = report.reference;  // later logs share the first log's frame
    }
    // The session's time span over every stream.
    double first = std::numeric_limits<double>::infinity(), last = -first;
    auto span = [&](double t) {
      first = std::min(first, t);
      last = std::max(last, t);
    };
    for (const auto& r : d->odometry) span(r.time_s);
    for (const auto& r : d->images) span(r.time_s);
    for (const auto& r : d->wifi) span(r.time_s);
    for (const auto& r : d->compass) span(r.time_s);
    for (const auto& r : d->pressure) span(r.time_s);
    for (const auto& r : d->ground_truth) span(r.time_s);
    if (!std::isfinite(first)) return Status::Error(path + ": empty data set");
    const double shift = std::isfinite(end_of_previous) ? end_of_previous + gap_s - first : 0.0;
    joined.session_start_times_s.push_back(first + shift);
    joined.session_names.push_back(d->name);
    // A still row at the session's start; rows at that same time add no motion (a row's speed
    // holds from the previous row's time to its own) and would repeat the time stamp.
    joined.odometry.push_back({first + shift, 0.0, 0.0});
    for (auto r : d->odometry) {
      r.time_s += shift;
      if (r.time_s > joined.odometry.back().time_s) joined.odometry.push_back(r);
    }
    for (auto r : d->images) {
      r.time_s += shift;
      r.file = fs::absolute(d->ImagePath(r)).string();
      joined.images.push_back(r);
    }
    for (auto r : d->wifi) {
      r.time_s += shift;
      joined.wifi.push_back(std::move(r));
    }
    for (auto r : d->compass) {
      r.time_s += shift;
      joined.compass.push_back(r);
    }
    for (auto r : d->pressure) {
      r.time_s += shift;
      joined.pressure.push_back(r);
    }
    for (auto r : d->ground_truth) {
      r.time_s += shift;
      joined.ground_truth.push_back(r);
    }
    if (joined.name.empty()) joined.name = d->name;
    end_of_previous = last + shift;
  }
  // Two sessions from files of one name (two folders' phone.txt) are told apart by their order.
  for (size_t i = 0; i < joined.session_names.size(); ++i) {
    const std::string name = joined.session_names[i];
    if (std::count(joined.session_names.begin(), joined.session_names.end(), name) > 1) {
      int k = 0;
      for (std::string& n : joined.session_names) {
        if (n == name) n += " (" + std::to_string(++k) + ")";
      }
    }
  }
  joined.name +=
      " +" + std::to_string(paths.size() - 1) + (paths.size() == 2 ? " session" : " sessions");
  return joined;
}

Status CopyImagesInto(Dataset* dataset, const std::string& folder,
                      const std::function<void(size_t, size_t)>& progress) {
  if (dataset->images.empty()) return Status::Ok();
  const fs::path images = fs::path(folder) / "images";
  std::error_code ec;
  fs::create_directories(images, ec);
  if (ec) return Status::Error(images.string() + ": cannot create: " + ec.message());
  BagImageReader bags;
  Ros2ImageReader ros2_bags;
  VideoFrameReader videos;
  std::vector<std::string> names(dataset->images.size());
  for (size_t i = 0; i < dataset->images.size(); ++i) {
    const std::string source = dataset->ImagePath(dataset->images[i]);
    std::string bytes, extension;
    std::string bag;
    uint64_t message = 0;
    if (!PathExists(source) && ParseBagImageReference(source, &bag, &message)) {
      StatusOr<EncodedImage> encoded = bags.Encoded(source);
      if (!encoded.ok()) return encoded.status();
      bytes.assign(encoded->bytes.begin(), encoded->bytes.end());
      extension = encoded->extension;
    } else if (!PathExists(source) && ParseRos2ImageReference(source, &bag, &message)) {
      StatusOr<EncodedImage> encoded = ros2_bags.Encoded(source);
      if (!encoded.ok()) return encoded.status();
      bytes.assign(encoded->bytes.begin(), encoded->bytes.end());
      extension = encoded->extension;
    } else if (!PathExists(source) && ParseVideoFrameReference(source, &bag, &message)) {
      // A video frame, decoded (to grey, as replays see it) and stored losslessly.
      StatusOr<GrayImage> frame = videos.Load(source);
      if (!frame.ok()) return frame.status();
      const cv::Mat grey(frame->height, frame->width, CV_8U, frame->pixels.data());
      std::vector<uint8_t> png;
      if (!cv::imencode(".png", grey, png)) return Status::Error(source + ": cannot encode PNG");
      bytes.assign(png.begin(), png.end());
      extension = "png";
    } else {
      StatusOr<std::string> read = ReadRegularFile(source, "image", uint64_t{1} << 30);
      if (!read.ok()) return read.status();
      bytes = std::move(read).value();
      extension = fs::path(source).extension().string();
      if (!extension.empty()) extension.erase(0, 1);
    }
    char name[32];
    std::snprintf(name, sizeof name, "%06zu", i);
    names[i] = std::string(name) + (extension.empty() ? "" : "." + extension);
    RATSLAM_RETURN_IF_ERROR(WriteFileAtomically((images / names[i]).string(), bytes, false));
    if (progress && (i + 1) % 500 == 0) progress(i + 1, dataset->images.size());
  }
  for (size_t i = 0; i < names.size(); ++i) dataset->images[i].file = names[i];
  dataset->folder = folder;
  dataset->image_folder = "images";
  if (progress) progress(names.size(), names.size());
  return Status::Ok();
}

}  // namespace ratslam::dataset
