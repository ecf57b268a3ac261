// The front end that matches nothing: every Wi-Fi scan is a frame with a new template, so the
// spine never closes a loop by appearance and the experience map is dead reckoning plus the
// loops other mechanisms add (Wi-Fi sequence loop closure alone, as in Kudo and Miura's
// odometry-and-Wi-Fi SLAM). The compass, when the data has one, is passed on.
#include <cmath>

#include "common/byte_buffer.h"
#include "fusion/front_end_internal.h"

namespace ratslam::fusion {
namespace front_end_internal {
namespace {

class NoViewFrontEnd : public FrontEnd {
 public:
  StatusOr<std::optional<FrameDecision>> OnImage(double, const GrayImage&) override {
    return std::optional<FrameDecision>();
  }
  StatusOr<std::optional<FrameDecision>> OnWifi(const WifiScan& scan) override {
    FrameDecision d;
    d.view.template_id = templates_++;
    d.view.is_new = true;
    d.view.time_s = scan.time_s;
    d.source = DecisionSource::kNew;
    return std::optional<FrameDecision>(d);
  }
  void OnCompass(double, double heading_rad) override { heading_rad_ = heading_rad; }
  std::optional<double> CompassHeading() const override { return heading_rad_; }
  bool WantsImages() const override { return false; }
  uint32_t size() const override { return templates_; }

  std::string EncodeState() const override {
    ByteWriter w;
    w.Pod(templates_);
    w.Optional(heading_rad_);
    return std::move(w.bytes());
  }
  Status DecodeState(const std::string& bytes) override {
    ByteReader r(bytes, "no-view front-end state");
    uint32_t templates = 0;
    std::optional<double> heading;
    if (!(r.Pod(&templates) && r.Optional(&heading) && r.AtEnd())) {
      return Status::Error(r.error().empty() ? "no-view front-end state: trailing bytes"
                                             : r.error());
    }
    if (heading && !std::isfinite(*heading)) {
      return Status::Error("no-view front-end state: heading is not finite");
    }
    templates_ = templates;
    heading_rad_ = heading;
    return Status::Ok();
  }

 private:
  uint32_t templates_ = 0;
  std::optional<double> heading_rad_;
};

}  // namespace

std::unique_ptr<FrontEnd> MakeNoViewFrontEnd() { return std::make_unique<NoViewFrontEnd>(); }

}  // namespace front_end_internal
}  // namespace ratslam::fusion
