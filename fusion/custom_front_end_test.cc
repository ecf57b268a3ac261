// The extension point of fusion/front_end.h ("Writing a front end"), shown by a complete front
// end of our own that the replay pipeline runs as [front_end] kind = "custom": each camera image
// shrinks to an 8x4 thumbnail of block means with its mean removed; the nearest stored thumbnail
// (sum of absolute differences per pixel) is a re-visit when under a threshold and not among
// the newest templates. A C++ user copies this class, changes Describe and Distance, and hands
// a factory to the pipeline or to ReplaySession (SessionEnvironment::custom_front_end).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/byte_buffer.h"
#include "common/scratch_dir.h"
#include "dataset/synthetic_dataset.h"
#include "fusion/front_end.h"
#include "fusion/replay_pipeline.h"

namespace ratslam::fusion {
namespace {

class ThumbnailFrontEnd : public FrontEnd {
 public:
  static constexpr int kWidth = 8, kHeight = 4;
  struct Options {
    double max_distance_grey = 3.0;   // mean absolute difference per thumbnail pixel, grey levels
    uint32_t recency_templates = 50;  // the newest this-many templates are no loop evidence
  };
  explicit ThumbnailFrontEnd(const Options& options) : options_(options) {}

  StatusOr<std::optional<FrameDecision>> OnImage(double time_s, const GrayImage& image) override {
    if (image.width < kWidth || image.height < kHeight) {
      return Status::Error("thumbnail front end: image smaller than 8x4");
    }
    const std::vector<float> thumbnail = Describe(image);
    FrameDecision d;
    d.view.time_s = time_s;
    const uint32_t n = size();
    uint32_t best = 0;
    double best_distance = std::numeric_limits<double>::infinity();
    for (uint32_t t = 0; t < n; ++t) {
      const double distance = Distance(thumbnail, t);
      if (distance < best_distance) {
        best_distance = distance;
        best = t;
      }
    }
    if (best_distance <= options_.max_distance_grey) {
      // A re-visit: inject unless the template is one of the newest (the place just left).
      d.view.template_id = best;
      d.recent = n - best <= options_.recency_templates;
      d.view.allow_injection = !d.recent;
      d.source = DecisionSource::kCamera;
    } else {
      thumbnails_.insert(thumbnails_.end(), thumbnail.begin(), thumbnail.end());
      d.view.template_id = n;  // new templates take the next id
      d.view.is_new = true;
      d.source = DecisionSource::kNew;
    }
    return std::optional<FrameDecision>(d);
  }
  // Wi-Fi scans and the compass are ignored (FrontEnd's defaults for OnWifi, OnCompass and
  // CompassHeading); images are the frames.
  bool WantsImages() const override { return true; }
  uint32_t size() const override {
    return static_cast<uint32_t>(thumbnails_.size() / (kWidth * kHeight));
  }
  std::string EncodeState() const override {
    ByteWriter w;
    w.PodVector(thumbnails_);
    return std::move(w.bytes());
  }
  Status DecodeState(const std::string& bytes) override {
    ByteReader r(bytes, "thumbnail front-end state");
    std::vector<float> thumbnails;
    if (!(r.PodVector(&thumbnails) && r.AtEnd())) {
      return Status::Error(r.error().empty() ? "thumbnail state: trailing bytes" : r.error());
    }
    if (thumbnails.size() % (kWidth * kHeight) != 0) {
      return Status::Error("thumbnail state: not a whole number of thumbnails");
    }
    for (float v : thumbnails) {
      if (!std::isfinite(v)) return Status::Error("thumbnail state: a value is not finite");
    }
    thumbnails_ = std::move(thumbnails);
    return Status::Ok();
  }

 private:
  static std::vector<float> Describe(const GrayImage& image) {
    std::vector<float> t(kWidth * kHeight);
    double mean = 0.0;
    for (int by = 0; by < kHeight; ++by) {
      for (int bx = 0; bx < kWidth; ++bx) {
        double sum = 0.0;
        int count = 0;
        for (int y = by * image.height / kHeight; y < (by + 1) * image.height / kHeight; ++y) {
          for (int x = bx * image.width / kWidth; x < (bx + 1) * image.width / kWidth; ++x) {
            sum += image.pixels[static_cast<size_t>(y) * image.width + x];
            ++count;
          }
        }
        t[by * kWidth + bx] = static_cast<float>(sum / count);
        mean += sum / count;
      }
    }
    mean /= kWidth * kHeight;
    for (float& v : t) v -= static_cast<float>(mean);
    return t;
  }
  double Distance(const std::vector<float>& thumbnail, uint32_t stored) const {
    const float* s = thumbnails_.data() + static_cast<size_t>(stored) * kWidth * kHeight;
    double sum = 0.0;
    for (int i = 0; i < kWidth * kHeight; ++i) sum += std::abs(thumbnail[i] - s[i]);
    return sum / (kWidth * kHeight);
  }

  Options options_;
  std::vector<float> thumbnails_;  // row-major, kWidth * kHeight per template
};

class CustomFrontEndTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new ScratchDir("ratslam_custom_front_end");
    dataset::SyntheticOptions o;
    o.laps = 2;
    StatusOr<dataset::Dataset> d = dataset::WriteSyntheticDataset(o, dir_->path().string());
    ASSERT_TRUE(d.ok()) << d.status().message();
    dataset_ = new dataset::Dataset(std::move(d).value());
    dataset_->folder = dir_->path().string();
  }
  static void TearDownTestSuite() {
    delete dataset_;
    delete dir_;
  }
  static PipelineOptions Options() {
    PipelineOptions o;
    o.sensors.front_end.kind = FrontEndKind::kCustom;
    return o;
  }
  static FrontEndResources Resources() {
    FrontEndResources r;
    r.custom = [] { return std::make_unique<ThumbnailFrontEnd>(ThumbnailFrontEnd::Options()); };
    return r;
  }
  static ScratchDir* dir_;
  static dataset::Dataset* dataset_;
};
ScratchDir* CustomFrontEndTest::dir_ = nullptr;
dataset::Dataset* CustomFrontEndTest::dataset_ = nullptr;

// The pipeline applies the custom front end's decisions: its re-visits become loop closures at
// places that truly repeat (ground truth, which the front end never sees).
TEST_F(CustomFrontEndTest, RevisitsCloseLoopsAtTrulyRepeatedPlaces) {
  dataset::FileImageLoader images;
  ReplayPipeline pipeline(Options(), *dataset_, &images, Resources());
  ASSERT_TRUE(pipeline.Run({}).ok());
  const auto& frames = pipeline.state().frames;
  ASSERT_EQ(frames.size(), dataset_->images.size());
  std::vector<double> created_s;  // by template
  size_t revisits = 0, near = 0;
  for (const FrameRecord& f : frames) {
    if (f.is_new) {
      ASSERT_EQ(f.template_id, created_s.size());
      created_s.push_back(f.time_s);
      continue;
    }
    if (f.recent) continue;
    ++revisits;
    const auto now = dataset::InterpolateGroundTruth(dataset_->ground_truth, f.time_s);
    const auto then =
        dataset::InterpolateGroundTruth(dataset_->ground_truth, created_s[f.template_id]);
    ASSERT_TRUE(now && then);
    if (std::hypot(now->x_m - then->x_m, now->y_m - then->y_m) < 3.0) ++near;
  }
  EXPECT_GT(revisits, 100u);
  // Chance: a random pair of places on a 120 m loop lies within 3 m about 5% of the time.
  EXPECT_GT(static_cast<double>(near) / static_cast<double>(revisits), 0.9)
      << near << " of " << revisits;
  EXPECT_GT(pipeline.slam().experience_map().num_links(),
            pipeline.slam().experience_map().num_experiences());
}

// Snapshot and Restore go through EncodeState, DecodeState and the factory: a run stopped
// halfway and restored into a new pipeline ends where an uninterrupted run ends.
TEST_F(CustomFrontEndTest, RestoredRunEndsWhereAnUninterruptedRunEnds) {
  dataset::FileImageLoader images;
  ReplayPipeline whole(Options(), *dataset_, &images, Resources());
  ASSERT_TRUE(whole.Run({}).ok());
  ReplayPipeline first(Options(), *dataset_, &images, Resources());
  ReplayControl half;
  half.until_time_s = dataset_->images[dataset_->images.size() / 2].time_s;
  ASSERT_TRUE(first.Run(half).ok());
  ReplayPipeline second(Options(), *dataset_, &images, Resources());
  ASSERT_TRUE(second.Restore(first.Snapshot()).ok());
  ASSERT_TRUE(second.Run({}).ok());
  EXPECT_EQ(second.Snapshot().front_end, whole.Snapshot().front_end);
  EXPECT_EQ(second.state().frames.size(), whole.state().frames.size());
  const ExperienceMap& a = whole.slam().experience_map();
  const ExperienceMap& b = second.slam().experience_map();
  ASSERT_EQ(a.num_experiences(), b.num_experiences());
  for (uint32_t i = 0; i < a.num_experiences(); ++i) {
    EXPECT_EQ(a.experience(i).x_m, b.experience(i).x_m);
    EXPECT_EQ(a.experience(i).y_m, b.experience(i).y_m);
  }
  // Bytes the front end did not write are refused, not trusted.
  ReplayPipeline::State corrupt = first.Snapshot();
  corrupt.front_end.resize(corrupt.front_end.size() - 3);
  ReplayPipeline third(Options(), *dataset_, &images, Resources());
  EXPECT_FALSE(third.Restore(corrupt).ok());
}

TEST_F(CustomFrontEndTest, CustomKindWithoutAFactoryIsRefused) {
  dataset::FileImageLoader images;
  EXPECT_THROW(ReplayPipeline(Options(), *dataset_, &images), std::invalid_argument);
}

}  // namespace
}  // namespace ratslam::fusion
