// Animation output: numbered PNG frames and, where OpenCV's video writer works, an MJPEG video.
#ifndef RATSLAM_VIEWER_ANIMATION_H_
#define RATSLAM_VIEWER_ANIMATION_H_

#include <memory>
#include <string>

#include "common/status.h"
#include "render/image.h"

namespace ratslam::viewer {

class AnimationWriter {
 public:
  // Frames go to folder/frame_000000.png, ...; the video to folder/animation.avi at `fps`.
  AnimationWriter(std::string folder, double fps);
  ~AnimationWriter();
  Status AddFrame(const render::RgbaImage& frame);
  // Finishes the video; returns whether one was written (false: PNG frames only).
  bool Close();
  int frames() const { return frames_; }

 private:
  struct Video;
  std::string folder_;
  double fps_;
  int frames_ = 0;
  std::unique_ptr<Video> video_;
};

}  // namespace ratslam::viewer

#endif  // RATSLAM_VIEWER_ANIMATION_H_
