// The descriptor front end: camera images are frames, each described by a vector computed
// outside this program (DescriptorTable). The best stored descriptor by cosine similarity (a dot
// product of unit vectors: one matrix-vector product over every template) is the active view
// when it reaches min_similarity and is not recent (the recency rule of the fused front end,
// eqs. 10-11 of the Wi-Fi RatSLAM paper); a recent one is re-used without injection; otherwise
// the descriptor becomes a new template. Pixels are never loaded.
#include <Eigen/Core>
#include <cmath>

#include "common/byte_buffer.h"
#include "common/number_text.h"
#include "fusion/front_end_internal.h"

namespace ratslam::fusion {
namespace front_end_internal {
namespace {

class DescriptorFrontEnd : public FrontEnd {
 public:
  DescriptorFrontEnd(const DescriptorOptions& options, std::shared_ptr<const DescriptorTable> table)
      : options_(options), table_(std::move(table)) {
    if (table_) dimensions_ = table_->dimensions();
  }

  StatusOr<std::optional<FrameDecision>> OnImage(double time_s, const GrayImage&) override {
    if (!table_) {
      return Status::Error(
          "the descriptor front end was given no descriptor file: feed descriptors directly");
    }
    const float* query = table_->At(time_s);
    if (query == nullptr) {
      return Status::Error("no descriptor for the image at " + ShortestNumber(time_s) +
                           " s (descriptors belong to the data set's own images)");
    }
    return std::optional<FrameDecision>(Decide(time_s, query));
  }

  StatusOr<std::optional<FrameDecision>> OnDescriptor(double time_s,
                                                      const std::vector<float>& values) override {
    if (values.empty() || (dimensions_ != 0 && values.size() != dimensions_)) {
      return Status::Error("a descriptor of " + std::to_string(values.size()) +
                           " dimensions; this front end's have " + std::to_string(dimensions_));
    }
    std::vector<float> unit;
    if (!UnitDescriptor(values.data(), values.size(), &unit)) {
      return Status::Error("a descriptor must be finite and not all zeros");
    }
    dimensions_ = values.size();
    return std::optional<FrameDecision>(Decide(time_s, unit.data()));
  }

  bool WantsImages() const override { return true; }
  bool NeedsPixels() const override { return false; }
  uint32_t size() const override { return static_cast<uint32_t>(created_time_s_.size()); }
  void SettleForLocalisation() override { settled_ = size(); }

  std::string EncodeState() const override {
    ByteWriter w;
    w.Pod(static_cast<uint64_t>(dimensions_));
    w.PodVector(unit_);
    w.PodVector(created_time_s_);
    return std::move(w.bytes());
  }
  Status DecodeState(const std::string& bytes) override {
    ByteReader r(bytes, "descriptor front-end state");
    uint64_t dimensions = 0;
    std::vector<float> unit;
    std::vector<double> created;
    if (!(r.Pod(&dimensions) && r.PodVector(&unit) && r.PodVector(&created) && r.AtEnd())) {
      return Status::Error(r.error().empty() ? "descriptor front-end state: trailing bytes"
                                             : r.error());
    }
    // Without a descriptor file (descriptors fed directly) the map's dimension is adopted.
    const size_t dims =
        dimensions_ != 0 || created.empty() ? dimensions_ : static_cast<size_t>(dimensions);
    if (!created.empty() && dimensions != dims) {
      return Status::Error("descriptor front-end state: the map's descriptors have " +
                           std::to_string(dimensions) + " dimensions, this data set's " +
                           std::to_string(dims));
    }
    // unit.size() == created.size() * dims, by division so that no product overflows.
    if (created.empty()
            ? !unit.empty()
            : dims == 0 || unit.size() % dims != 0 || unit.size() / dims != created.size()) {
      return Status::Error("descriptor front-end state: " + std::to_string(unit.size()) +
                           " values for " + std::to_string(created.size()) + " templates");
    }
    if (!AllFinite(created)) {
      return Status::Error("descriptor front-end state: a template time is not finite");
    }
    for (size_t i = 0; i < created.size(); ++i) {
      double norm2 = 0.0;
      for (size_t k = 0; k < dims; ++k) {
        const double v = unit[i * dims + k];
        norm2 += v * v;
      }
      // Unit length to float rounding; anything else (NaN included) is not a stored descriptor.
      if (!(std::abs(norm2 - 1.0) < 1e-3)) {
        return Status::Error("descriptor front-end state: template " + std::to_string(i) +
                             " is not a unit vector");
      }
    }
    dimensions_ = dims;
    unit_ = std::move(unit);
    created_time_s_ = std::move(created);
    return Status::Ok();
  }

 private:
  // The best stored descriptor by cosine similarity (`query` is a unit vector of dimensions_).
  FrameDecision Decide(double time_s, const float* query) {
    const size_t n = created_time_s_.size();
    FrameDecision d;
    d.view.time_s = time_s;
    if (n > 0) {
      using Matrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
      const Eigen::Map<const Matrix> stored(unit_.data(), static_cast<Eigen::Index>(n),
                                            static_cast<Eigen::Index>(dimensions_));
      const Eigen::Map<const Eigen::VectorXf> q(query, static_cast<Eigen::Index>(dimensions_));
      scores_.resize(static_cast<Eigen::Index>(n));
      scores_.noalias() = stored * q;
      Eigen::Index best = 0;
      const float similarity = scores_.maxCoeff(&best);  // the first of equal maxima
      if (similarity >= options_.min_similarity) {
        const bool old_enough =
            OldEnough(static_cast<int64_t>(n), best, time_s, created_time_s_[best],
                      options_.recency_templates, options_.recency_s, settled_);
        d.view.template_id = static_cast<uint32_t>(best);
        d.view.is_new = false;
        d.view.allow_injection = old_enough;
        d.source = DecisionSource::kCamera;
        d.recent = !old_enough;
        return d;
      }
    }
    unit_.insert(unit_.end(), query, query + dimensions_);
    created_time_s_.push_back(time_s);
    d.view.template_id = static_cast<uint32_t>(n);
    d.view.is_new = true;
    d.source = DecisionSource::kNew;
    return d;
  }

  DescriptorOptions options_;
  std::shared_ptr<const DescriptorTable> table_;
  size_t dimensions_ = 0;
  std::vector<float> unit_;             // row-major templates x dimensions_, unit rows
  std::vector<double> created_time_s_;  // by template
  int64_t settled_ = 0;                 // templates from a saved map (SettleForLocalisation)
  Eigen::VectorXf scores_;              // scratch: one similarity per template
};

}  // namespace

std::unique_ptr<FrontEnd> MakeDescriptorFrontEnd(const DescriptorOptions& options,
                                                 std::shared_ptr<const DescriptorTable> table) {
  return std::make_unique<DescriptorFrontEnd>(options, std::move(table));
}

}  // namespace front_end_internal
}  // namespace ratslam::fusion
