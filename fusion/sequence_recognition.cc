// Sequence recognition in front of an image front end ([sequence] recognise_views): the
// recogniser keeps every camera frame seen (patch normalised, sensors/sequence_matcher.h) with
// the template the frame ended on. Each new frame is first a query: when the newest
// sequence_length frames, as a straight line through the difference matrix, match a stretch of
// the route older than recency_frames with at least min_confidence, the frame re-uses the
// template of the frame it matched (a loop closure, with injection); otherwise the wrapped front
// end decides. Either way the frame then joins the references. After Milford and Wyeth, SeqSLAM
// (ICRA 2012), used online: the references grow as the route is driven, so a later traverse in
// other weather recognises the first by its sequences where single frames fail.
//
// Cost: a frame is compared with every earlier frame (one SIMD sum of absolute differences each,
// 64x32 frames: about 0.1 ms per thousand), so a run's matching grows with the square of its
// frames: fine for thousands of frames, not for hundreds of thousands.
#include <algorithm>
#include <cmath>
#include <limits>

#include "common/byte_buffer.h"
#include "fusion/front_end_internal.h"

namespace ratslam::fusion {
namespace front_end_internal {
namespace {

constexpr uint32_t kNoTemplate = std::numeric_limits<uint32_t>::max();

class SequenceRecognition : public FrontEnd {
 public:
  SequenceRecognition(std::unique_ptr<FrontEnd> inner,
                      const sensors::SequenceMatcherOptions& options)
      : inner_(std::move(inner)), options_(options), matcher_(options) {}

  StatusOr<std::optional<FrameDecision>> OnImage(double time_s, const GrayImage& image) override {
    sensors::PreparedFrame frame =
        sensors::PrepareFrame(image.pixels.data(), image.width, image.height, options_);
    const int64_t frames = static_cast<int64_t>(matcher_.references());
    const int64_t searchable =
        std::max<int64_t>(settled_, frames - static_cast<int64_t>(options_.recency_frames));
    StatusOr<sensors::SequenceMatcher::Result> r =
        matcher_.AddQuery(frame, 1, static_cast<int>(std::max<int64_t>(searchable, 0)));
    if (!r.ok()) return r.status();
    const sensors::SequenceMatch& m = r->sequence;
    const bool confident =
        !m.declined && searchable >= options_.min_references &&
        matcher_.queries_in_sequence() >= static_cast<size_t>(options_.sequence_length) &&
        m.confidence >= options_.min_confidence;
    // The previous frame's confident match must lie just behind this one (the line goes on): an
    // isolated confident frame, or one whose best line jumped elsewhere, is not recognised.
    const int64_t step = confident && previous_ >= 0 ? m.reference - previous_ : -1;
    const bool continues =
        step >= 0 && step <= static_cast<int64_t>(std::ceil(options_.max_velocity)) + 1;
    previous_ = confident ? m.reference : -1;
    std::optional<FrameDecision> decision;
    if (frame.blank) {
      // No view at all: a frame without contrast (a tunnel, night, a lens cap) looks like every
      // other such frame, so the wrapped front end would match it to any earlier one anywhere.
      // The pose cells keep integrating odometry through it.
    } else if (continues && template_of_[m.reference] != kNoTemplate) {
      FrameDecision d;
      d.view.time_s = time_s;
      d.view.template_id = template_of_[m.reference];
      d.view.is_new = false;
      d.view.allow_injection = true;
      d.source = DecisionSource::kCamera;
      decision = d;
    } else {
      StatusOr<std::optional<FrameDecision>> inner = inner_->OnImage(time_s, image);
      if (!inner.ok()) return inner.status();
      decision = inner.value();
    }
    RATSLAM_RETURN_IF_ERROR(matcher_.AddReference(std::move(frame)));
    template_of_.push_back(decision ? decision->view.template_id : kNoTemplate);
    return decision;
  }

  StatusOr<std::optional<FrameDecision>> OnWifi(const WifiScan& scan) override {
    return inner_->OnWifi(scan);
  }
  void OnCompass(double time_s, double heading_rad) override {
    inner_->OnCompass(time_s, heading_rad);
  }
  Status OnPressure(double time_s, double pressure_hpa) override {
    return inner_->OnPressure(time_s, pressure_hpa);
  }
  std::optional<double> CompassHeading() const override { return inner_->CompassHeading(); }
  bool WantsImages() const override { return true; }
  bool NeedsPixels() const override { return true; }
  uint32_t size() const override { return inner_->size(); }
  void OnSessionStart(double start_s) override { inner_->OnSessionStart(start_s); }
  void OnWalking(bool walking) override { inner_->OnWalking(walking); }
  void OnVerifiedRevisit(double current_time_s, double past_time_s) override {
    inner_->OnVerifiedRevisit(current_time_s, past_time_s);
  }
  std::optional<FrontEndCalibration> Learnt() const override { return inner_->Learnt(); }
  Status Calibrate(const FrontEndCalibration& calibration) override {
    return inner_->Calibrate(calibration);
  }
  FrontEndReport Report() const override { return inner_->Report(); }
  void SettleForLocalisation() override {
    settled_ = static_cast<int64_t>(matcher_.references());
    inner_->SettleForLocalisation();
  }
  std::optional<int> TemplateFloor(uint32_t id) const override { return inner_->TemplateFloor(id); }

  std::string EncodeState() const override {
    ByteWriter w;
    w.String(inner_->EncodeState());
    w.PodVector(template_of_);
    w.Pod<int64_t>(settled_);
    w.Pod<int64_t>(previous_);
    const sensors::SequenceMatcher::State state = matcher_.state();
    w.Count(state.references.size());
    for (const sensors::PreparedFrame& f : state.references) {
      w.Pod<int32_t>(f.width);
      w.Pod<int32_t>(f.height);
      w.Bool(f.blank);
      w.PodVector(f.bytes);
    }
    w.Count(state.rows.size());
    for (const sensors::SequenceMatcher::Row& row : state.rows) {
      w.PodVector(row.enhanced);
      w.Pod(row.neutral);
      w.Bool(row.blank);
    }
    return std::move(w.bytes());
  }

  Status DecodeState(const std::string& bytes) override {
    ByteReader r(bytes, "sequence recognition state");
    std::string inner;
    std::vector<uint32_t> template_of;
    int64_t settled = 0, previous = -1;
    sensors::SequenceMatcher::State state;
    size_t references = 0, rows = 0;
    // A frame takes at least its two sizes, a flag and a byte count; a row a count, a float and a
    // flag: the counts cannot claim more than the bytes hold.
    bool ok = r.String(&inner) && r.PodVector(&template_of) && r.Pod(&settled) &&
              r.Pod(&previous) && r.Count(4 + 4 + 1 + 8, &references);
    for (size_t i = 0; ok && i < references; ++i) {
      sensors::PreparedFrame f;
      int32_t width = 0, height = 0;
      ok = r.Pod(&width) && r.Pod(&height) && r.Bool(&f.blank) && r.PodVector(&f.bytes);
      f.width = width;
      f.height = height;
      state.references.push_back(std::move(f));
    }
    ok = ok && r.Count(8 + 4 + 1, &rows);
    for (size_t i = 0; ok && i < rows; ++i) {
      sensors::SequenceMatcher::Row row;
      ok = r.PodVector(&row.enhanced) && r.Pod(&row.neutral) && r.Bool(&row.blank);
      state.rows.push_back(std::move(row));
    }
    if (!(ok && r.AtEnd())) {
      return Status::Error(r.error().empty() ? "sequence recognition state: trailing bytes"
                                             : r.error());
    }
    if (template_of.size() != state.references.size() || settled < 0 ||
        settled > static_cast<int64_t>(template_of.size()) || previous < -1 ||
        previous >= static_cast<int64_t>(template_of.size())) {
      return Status::Error("sequence recognition state: " + std::to_string(template_of.size()) +
                           " frame templates for " + std::to_string(state.references.size()) +
                           " frames (settled " + std::to_string(settled) + ")");
    }
    // The wrapped front end is decoded first (the frames' templates are checked against it) and
    // put back as it was when anything after fails: a refused state changes nothing.
    const std::string before = inner_->EncodeState();
    RATSLAM_RETURN_IF_ERROR(inner_->DecodeState(inner));
    Status fits = Status::Ok();
    for (uint32_t t : template_of) {
      if (t != kNoTemplate && t >= inner_->size()) {
        fits = Status::Error("sequence recognition state: a frame names template " +
                             std::to_string(t) + " of " + std::to_string(inner_->size()));
        break;
      }
    }
    if (fits.ok()) fits = matcher_.SetState(std::move(state));
    if (!fits.ok()) {
      (void)inner_->DecodeState(before);  // bytes it wrote itself: taken back
      return fits;
    }
    template_of_ = std::move(template_of);
    settled_ = settled;
    previous_ = previous;
    return Status::Ok();
  }

 private:
  std::unique_ptr<FrontEnd> inner_;
  sensors::SequenceMatcherOptions options_;
  sensors::SequenceMatcher matcher_;
  std::vector<uint32_t> template_of_;  // by frame: the template it ended on
  int64_t settled_ = 0;                // frames from a saved map: never too recent
  int64_t previous_ = -1;              // the previous frame's confident match, -1 if none
};

}  // namespace

std::unique_ptr<FrontEnd> MakeSequenceRecognition(std::unique_ptr<FrontEnd> inner,
                                                  const sensors::SequenceMatcherOptions& options) {
  return std::make_unique<SequenceRecognition>(std::move(inner), options);
}

}  // namespace front_end_internal
}  // namespace ratslam::fusion
