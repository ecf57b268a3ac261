// The classic RatSLAM camera front end (OpenRatSLAM's matcher): images are frames.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/byte_buffer.h"
#include "fusion/front_end_internal.h"

namespace ratslam::fusion {
namespace front_end_internal {
namespace {

class ClassicCameraFrontEnd : public FrontEnd {
 public:
  explicit ClassicCameraFrontEnd(const sensors::ClassicCameraOptions& options)
      : matcher_(options) {}

  StatusOr<std::optional<FrameDecision>> OnImage(double time_s, const GrayImage& image) override {
    StatusOr<ViewDecision> view = matcher_.Observe(ViewOf(image), time_s);
    if (!view.ok()) return view.status();
    FrameDecision d;
    d.view = view.value();
    d.source = d.view.is_new ? DecisionSource::kNew : DecisionSource::kCamera;
    return std::optional<FrameDecision>(d);
  }
  bool WantsImages() const override { return true; }
  uint32_t size() const override { return matcher_.size(); }

  std::string EncodeState() const override {
    ByteWriter w;
    w.Pod(matcher_.state().template_count);
    w.PodVector(matcher_.state().templates);
    return std::move(w.bytes());
  }
  Status DecodeState(const std::string& bytes) override {
    ByteReader r(bytes, "classic camera state");
    sensors::ClassicCameraMatcher::State state;
    if (!(r.Pod(&state.template_count) && r.PodVector(&state.templates) && r.AtEnd())) {
      return Status::Error(r.error().empty() ? "classic camera state: trailing bytes" : r.error());
    }
    return matcher_.SetState(std::move(state));
  }

 private:
  sensors::ClassicCameraMatcher matcher_;
};

}  // namespace

std::unique_ptr<FrontEnd> MakeClassicCameraFrontEnd(const sensors::ClassicCameraOptions& options) {
  return std::make_unique<ClassicCameraFrontEnd>(options);
}

}  // namespace front_end_internal
}  // namespace ratslam::fusion
