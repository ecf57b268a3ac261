// Video files as data sets, what OpenRatSLAM's original sample and xRatSLAM read: a video
// (anything OpenCV's video reader opens: AVI, MP4, MKV, ...) and, beside it, an odometry log with
// one row per frame in OpenRatSLAM's format (../shared/reference/openratslam-facts.md, section 5:
// a header line, then `sec, nsec, trans_vel (m/s), rot_vel (rad/s)` and ignored columns).
//
// Frames stay in the video: a data set read from a video names frame n `<video>#<n>`, and
// FileImageLoader decodes it (reading on when frames are asked for in order, seeking otherwise).
#ifndef RATSLAM_DATASET_VIDEO_H_
#define RATSLAM_DATASET_VIDEO_H_

#include <cstdint>
#include <memory>
#include <string>

#include "common/schema.h"
#include "common/status.h"
#include "dataset/dataset.h"
#include "dataset/image_loader.h"

namespace ratslam::dataset {

// [video] in the configuration: how a video's frames get times and odometry.
struct VideoOptions {
  double frame_rate_hz = 0.0;  // > 0: frame n at n / rate; 0: the container's time stamps
  std::string odometry_log;    // empty: <video stem>.txt beside the video, if there is one

  bool IsValid(std::string* error) const;

  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("frame_rate_hz", frame_rate_hz,
      "frame n is at n / this (s); 0: the container's time stamps (an odometry log's own times "
      "take precedence)",
      schema::Unit("Hz").NonNegative());
    v("odometry_log", odometry_log,
      "OpenRatSLAM odometry log (sec, nsec, trans_vel, rot_vel per frame); empty: the video's "
      "name with .txt, when it exists",
      schema::Any());
  }
};

// Whether `path` names a video file by its extension (avi, mp4, mkv, mov, mpg, mpeg, webm, m4v).
bool LooksLikeVideo(const std::string& path);

// One image row per frame; with an odometry log, frame n takes row n's time (seconds after the
// first row) and the rows become the odometry (the first row moves nothing), so the log must have
// at least as many rows as the video has frames. Errors name the file, line and column.
StatusOr<Dataset> ReadVideo(const std::string& path, const VideoOptions& options);

// `path` names a frame of a video (`<file>#<n>` where the file is no bag): splits it.
bool ParseVideoFrameReference(const std::string& path, std::string* video, uint64_t* frame);

// Decodes frames by reference, keeping the last video open. Thread-safe.
class VideoFrameReader {
 public:
  VideoFrameReader();
  ~VideoFrameReader();
  VideoFrameReader(const VideoFrameReader&) = delete;
  VideoFrameReader& operator=(const VideoFrameReader&) = delete;

  StatusOr<GrayImage> Load(const std::string& reference);

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

// Writes `dataset`'s images as a Motion-JPEG AVI (best quality, grey) at `rate_hz` and, when it
// has odometry, `<video stem>.txt` in OpenRatSLAM's log format (frame n's time and the odometry
// row at that time; the data set must have one odometry row per image, at the image's time).
// For tests and for trying video input with the synthetic loop.
Status WriteVideo(const Dataset& dataset, ImageLoader* images, const std::string& path,
                  double rate_hz);

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_VIDEO_H_
