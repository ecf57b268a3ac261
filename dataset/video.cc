#include "dataset/video.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <vector>

#include "common/file_util.h"
#include "common/text_file.h"
#include "dataset/opencv_gray.h"
#include "dataset/rosbag.h"

namespace ratslam::dataset {
namespace fs = std::filesystem;

namespace {

constexpr uint64_t kMaxFrames = 10'000'000;

bool ParseNumber(const std::string& text, double* out) {
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  while (begin < end && std::isspace(static_cast<unsigned char>(*begin))) ++begin;
  while (end > begin && std::isspace(static_cast<unsigned char>(end[-1]))) --end;
  const auto r = std::from_chars(begin, end, *out);
  return begin != end && r.ec == std::errc() && r.ptr == end && std::isfinite(*out);
}

struct LogRow {
  double time_s;
  double trans_m_per_s;
  double rot_rad_per_s;
};

// OpenRatSLAM's odometry log: a header line, then sec, nsec, trans_vel, rot_vel[, ...] per row,
// separated by commas or white space.
StatusOr<std::vector<LogRow>> ReadOdometryLog(const std::string& path) {
  std::ifstream in;
  RATSLAM_RETURN_IF_ERROR(OpenRegularFile(path, "odometry log", &in));
  std::string line;
  std::vector<LogRow> rows;
  double first_sec = 0.0, first_nsec = 0.0;
  static const char* const kColumns[] = {"sec", "nsec", "trans_vel", "rot_vel"};
  for (int number = 1; std::getline(in, line); ++number) {
    if (number == 1) continue;  // the header
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::vector<std::string> cells;
    std::string cell;
    for (char c : line) {
      if (c == ',' || c == ' ' || c == '\t' || c == '\r') {
        if (!cell.empty()) cells.push_back(cell);
        cell.clear();
      } else {
        cell += c;
      }
    }
    if (!cell.empty()) cells.push_back(cell);
    const std::string where = path + ":" + std::to_string(number);
    if (cells.size() < 4) {
      return Status::Error(where + ": expected sec, nsec, trans_vel, rot_vel; found " +
                           std::to_string(cells.size()) + " columns");
    }
    double v[4];
    for (int i = 0; i < 4; ++i) {
      if (!ParseNumber(cells[static_cast<size_t>(i)], &v[i])) {
        return Status::Error(where + ": column '" + kColumns[i] + "': not a finite number: '" +
                             cells[static_cast<size_t>(i)] + "'");
      }
    }
    if (v[0] < 0 || v[0] != std::floor(v[0]) || v[0] > 1e12) {
      return Status::Error(where + ": column 'sec': not a whole number of seconds");
    }
    if (v[1] < 0 || v[1] >= 1e9 || v[1] != std::floor(v[1])) {
      return Status::Error(where + ": column 'nsec': not a whole number in [0, 1e9)");
    }
    if (rows.empty()) {
      first_sec = v[0];
      first_nsec = v[1];
    }
    const double t = (v[0] - first_sec) + (v[1] - first_nsec) * 1e-9;
    if (!rows.empty() && t < rows.back().time_s) {
      return Status::Error(where + ": time goes backwards");
    }
    rows.push_back({t, v[2], v[3]});
  }
  return rows;
}

// A file through FFmpeg, or OpenCV's own Motion-JPEG reader. Never CAP_ANY: that also probes
// camera back ends (GStreamer, USB device lists), which leak and print.
// OpenCV's warnings about the back ends it tried go to stderr (the callers' errors say enough);
// they are silenced only while opening, and the caller's log level is restored.
bool OpenFile(cv::VideoCapture& capture, const std::string& path) {
  const cv::utils::logging::LogLevel before =
      cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  struct Restore {
    cv::utils::logging::LogLevel level;
    ~Restore() { cv::utils::logging::setLogLevel(level); }
  } restore{before};
  if (capture.open(path, cv::CAP_FFMPEG)) return true;
  return capture.open(path, cv::CAP_OPENCV_MJPEG);
}

}  // namespace

bool VideoOptions::IsValid(std::string* error) const { return schema::CheckFields(*this, error); }

bool LooksLikeVideo(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  static const char* const kExtensions[] = {".avi", ".mp4",  ".mkv",  ".mov",
                                            ".mpg", ".mpeg", ".webm", ".m4v"};
  return std::any_of(std::begin(kExtensions), std::end(kExtensions),
                     [&](const char* e) { return ext == e; });
}

bool ParseVideoFrameReference(const std::string& path, std::string* video, uint64_t* frame) {
  const size_t hash = path.rfind('#');
  if (hash == std::string::npos) return false;
  const std::string digits = path.substr(hash + 1);
  if (digits.empty() || digits.size() > 15 ||
      !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return false;
  }
  const std::string file = path.substr(0, hash);
  if (!LooksLikeVideo(file)) return false;
  *video = file;
  *frame = std::stoull(digits);
  return true;
}

StatusOr<Dataset> ReadVideo(const std::string& path, const VideoOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) return Status::Error("video." + error);
  if (!IsRegularFile(path)) return Status::Error(path + ": not a file");
  cv::VideoCapture capture;
  try {
    OpenFile(capture, path);
  } catch (const cv::Exception& e) {
    return Status::Error(path + ": OpenCV's video reader failed: " + e.what());
  }
  if (!capture.isOpened()) {
    return Status::Error(path +
                         ": OpenCV's video reader cannot open it (unknown container or "
                         "codec, or not a video)");
  }
  const double fps =
      options.frame_rate_hz > 0 ? options.frame_rate_hz : capture.get(cv::CAP_PROP_FPS);
  uint64_t frames = 0;
  try {
    while (frames < kMaxFrames && capture.grab()) ++frames;
  } catch (const cv::Exception& e) {
    return Status::Error(path + ": frame " + std::to_string(frames) + ": " + e.what());
  }
  if (frames == 0) return Status::Error(path + ": the video has no frames");
  Dataset d;
  d.name = fs::path(path).stem().string();
  d.folder = path;
  d.image_folder = "";
  std::string log = options.odometry_log;
  if (log.empty()) {
    const fs::path beside = fs::path(path).replace_extension(".txt");
    if (IsRegularFile(beside)) log = beside.string();
  }
  std::vector<LogRow> rows;
  if (!log.empty()) {
    StatusOr<std::vector<LogRow>> read = ReadOdometryLog(log);
    if (!read.ok()) return read.status();
    rows = std::move(read).value();
    if (rows.size() < frames) {
      return Status::Error(log + ": " + std::to_string(rows.size()) + " rows for the " +
                           std::to_string(frames) + " frames of " + path + " (one row per frame)");
    }
  } else if (!(fps > 0) || !std::isfinite(fps)) {
    return Status::Error(path +
                         ": the container gives no frame rate: set [video] "
                         "frame_rate_hz or give an odometry log");
  }
  const std::string reference = fs::absolute(path).string() + "#";
  for (uint64_t n = 0; n < frames; ++n) {
    ImageRow image;
    image.time_s = rows.empty() ? static_cast<double>(n) / fps : rows[n].time_s;
    image.file = reference + std::to_string(n);
    image.line = static_cast<int>(std::min<uint64_t>(n, 0x7fffffff));
    d.images.push_back(image);
    // The first row is the time reference only: it moves nothing.
    if (!rows.empty()) {
      d.odometry.push_back({rows[n].time_s, n == 0 ? 0.0 : rows[n].trans_m_per_s,
                            n == 0 ? 0.0 : rows[n].rot_rad_per_s});
    }
  }
  return d;
}

class VideoFrameReader::Impl {
 public:
  std::mutex mutex;
  std::string path;
  cv::VideoCapture capture;
  uint64_t next = 0;
};

VideoFrameReader::VideoFrameReader() : impl_(std::make_unique<Impl>()) {}
VideoFrameReader::~VideoFrameReader() = default;

StatusOr<GrayImage> VideoFrameReader::Load(const std::string& reference) {
  std::string path;
  uint64_t frame = 0;
  if (!ParseVideoFrameReference(reference, &path, &frame)) {
    return Status::Error(reference + ": not a frame reference <video>#<frame>");
  }
  std::lock_guard<std::mutex> lock(impl_->mutex);
  cv::Mat mat;
  try {
    if (path != impl_->path || !impl_->capture.isOpened()) {
      impl_->path.clear();
      if (!OpenFile(impl_->capture, path)) return Status::Error(path + ": cannot open the video");
      impl_->path = path;
      impl_->next = 0;
    }
    if (frame != impl_->next) {  // reading on is exact; seeking is the codec's business
      if (frame < impl_->next) {
        impl_->capture.release();
        if (!OpenFile(impl_->capture, path)) return Status::Error(path + ": cannot open the video");
        impl_->next = 0;
      }
      while (impl_->next < frame && impl_->capture.grab()) ++impl_->next;
    }
    if (impl_->next != frame || !impl_->capture.read(mat) || mat.empty()) {
      impl_->path.clear();
      return Status::Error(reference + ": cannot read the frame");
    }
    ++impl_->next;
  } catch (const cv::Exception& e) {
    impl_->path.clear();
    return Status::Error(reference + ": " + e.what());
  }
  return GrayFromMat(mat, reference);
}

Status WriteVideo(const Dataset& dataset, ImageLoader* images, const std::string& path,
                  double rate_hz) {
  if (dataset.images.empty()) return Status::Error(path + ": the data set has no images");
  if (!(rate_hz > 0) || !std::isfinite(rate_hz)) return Status::Error(path + ": bad frame rate");
  const bool with_log = !dataset.odometry.empty();
  if (with_log) {
    if (dataset.odometry.size() != dataset.images.size()) {
      return Status::Error(path + ": an odometry log needs one odometry row per image");
    }
    for (size_t i = 0; i < dataset.images.size(); ++i) {
      if (dataset.odometry[i].time_s != dataset.images[i].time_s || dataset.images[i].time_s < 0) {
        return Status::Error(path + ": image " + std::to_string(i) +
                             " and its odometry row have different or negative times");
      }
    }
  }
  cv::VideoWriter writer;
  std::string log;
  try {
    for (size_t i = 0; i < dataset.images.size(); ++i) {
      StatusOr<GrayImage> image = images->Load(dataset.ImagePath(dataset.images[i]));
      if (!image.ok()) return image.status();
      if (i == 0) {
        writer.open(path, cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'),
                    rate_hz, cv::Size(image->width, image->height), true);
        if (!writer.isOpened()) return Status::Error(path + ": cannot write the video");
        writer.set(cv::VIDEOWRITER_PROP_QUALITY, 100);
      }
      // Colour frames: FFmpeg's decoder misreads OpenCV's single-channel Motion JPEG.
      cv::Mat colour;
      cv::cvtColor(cv::Mat(image->height, image->width, CV_8U, image->pixels.data()), colour,
                   cv::COLOR_GRAY2BGR);
      writer.write(colour);
      if (with_log) {
        const OdometryRow& row = dataset.odometry[i];
        const double whole = std::floor(row.time_s);
        int64_t nsec = std::llround((row.time_s - whole) * 1e9);
        int64_t sec = 1000000000 + static_cast<int64_t>(whole);
        if (nsec >= 1000000000) {
          nsec -= 1000000000;
          ++sec;
        }
        char line[160];
        std::snprintf(line, sizeof line, "%lld,%lld,%.17g,%.17g\n", static_cast<long long>(sec),
                      static_cast<long long>(nsec), row.forward_speed_m_per_s,
                      row.turn_rate_rad_per_s);
        log += line;
      }
    }
    writer.release();
  } catch (const cv::Exception& e) {
    return Status::Error(path + ": " + e.what());
  }
  if (with_log) {
    std::ofstream out(fs::path(path).replace_extension(".txt"));
    out << "sec,nsec,trans_vel,rot_vel\n" << log;
    if (!out.flush()) return Status::Error(path + ": cannot write the odometry log");
  }
  return Status::Ok();
}

}  // namespace ratslam::dataset
