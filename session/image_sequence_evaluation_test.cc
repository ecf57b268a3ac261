#include "session/image_sequence_evaluation.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/random.h"
#include "dataset/descriptor_file.h"

namespace ratslam::session {
namespace {

QueryAnswer Answer(int truth, int reference, double confidence, std::vector<int> top = {}) {
  QueryAnswer a;
  a.truth = truth;
  if (reference < 0) return a;  // declined
  a.match.declined = false;
  a.match.reference = reference;
  a.match.confidence = confidence;
  a.match.candidates.push_back({reference, 0.0});
  for (int t : top) a.match.candidates.push_back({t, 1.0});
  return a;
}

// Five queries by hand, at a tolerance of one frame: by confidence 0.9 right, 0.8 right (one
// frame off), 0.5 wrong (but right in its top five), 0.3 wrong (two frames off); one declined.
// Recall@1 2/5, recall@5 3/5; the curve (recall, precision): (0.2, 1), (0.4, 1), (0.4, 2/3),
// (0.4, 1/2); average precision 0.2 + 0.2; recall at 100 % precision 0.4. At two frames the
// last is right: (0.6, 3/4) adds 0.2 * 3/4. A query without a true place is not counted.
TEST(PlaceRecognitionMetricsTest, KnownAnswersByHand) {
  const std::vector<QueryAnswer> answers = {Answer(10, 10, 0.9),       Answer(20, 21, 0.8),
                                            Answer(30, 50, 0.5, {31}), Answer(40, 42, 0.3),
                                            Answer(50, -1, 0.0),       Answer(-1, 7, 5.0)};
  const PlaceRecognitionMetrics m = MetricsOf(answers, 1);
  EXPECT_EQ(m.queries, 5u);
  EXPECT_EQ(m.declined, 1u);
  EXPECT_DOUBLE_EQ(m.recall_at_1, 2.0 / 5);  // 42 is two frames from 40: wrong at tolerance 1
  EXPECT_DOUBLE_EQ(m.recall_at_5, 3.0 / 5);
  ASSERT_EQ(m.curve.size(), 4u);
  EXPECT_DOUBLE_EQ(m.curve[2].precision, 2.0 / 3);
  EXPECT_DOUBLE_EQ(m.pr_auc, 0.2 + 0.2);
  EXPECT_DOUBLE_EQ(m.recall_at_100_precision, 0.4);
  const PlaceRecognitionMetrics wide = MetricsOf(answers, 2);
  EXPECT_DOUBLE_EQ(wide.recall_at_1, 3.0 / 5);
  EXPECT_DOUBLE_EQ(wide.pr_auc, 0.2 + 0.2 + 0.2 * 3 / 4);
}

// Tied confidences are accepted together: two right and one wrong at one threshold give one
// point of precision 2/3, and recall at 100 % precision stays 0.
TEST(PlaceRecognitionMetricsTest, TiesAreOneThreshold) {
  const PlaceRecognitionMetrics m =
      MetricsOf({Answer(1, 1, 0.5), Answer(2, 9, 0.5), Answer(3, 3, 0.5)}, 0);
  ASSERT_EQ(m.curve.size(), 1u);
  EXPECT_DOUBLE_EQ(m.curve[0].precision, 2.0 / 3);
  EXPECT_DOUBLE_EQ(m.recall_at_100_precision, 0.0);
}

TEST(PairQueriesTest, ByNameThenByPositionElseAnError) {
  EXPECT_EQ(PairQueriesWithReferences({"a.png", "b.png", "c.png"}, {"c.png", "a.png"}, "").value(),
            (std::vector<int>{2, 0}));
  EXPECT_EQ(PairQueriesWithReferences({"a.png", "b.png"}, {"x.png", "y.png"}, "").value(),
            (std::vector<int>{0, 1}));
  const auto e = PairQueriesWithReferences({"a.png", "b.png"}, {"x.png"}, "");
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.status().message().find("--ground-truth"), std::string::npos);
}

namespace fs = std::filesystem;

class ImageFoldersTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("ratslam_image_sequence_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_ / "ref");
    fs::create_directories(root_ / "query");
  }
  void TearDown() override { fs::remove_all(root_); }
  // A 64x32 texture of place `place`, with Gaussian noise of `sigma` grey levels.
  void Write(const fs::path& path, int place, double sigma, Random* noise) {
    Random texture(100 + place);
    cv::Mat image(32, 64, CV_8UC1);
    for (int y = 0; y < 32; ++y) {
      for (int x = 0; x < 64; ++x) {
        image.at<uint8_t>(y, x) =
            cv::saturate_cast<uint8_t>(texture.Uniform(20, 230) + noise->Gaussian(0, sigma));
      }
    }
    ASSERT_TRUE(cv::imwrite(path.string(), image));
  }
  fs::path root_;
};

// Forty places written as PNG files; the queries, the same places with noise and named alike, are
// placed exactly by single frames and, once a sequence is full, by sequences (the oracle is the
// file name). A file that is not an image
// is an error naming it.
TEST_F(ImageFoldersTest, PlacesEveryQueryByNameAndNamesABadFile) {
  Random noise(9);
  for (int i = 0; i < 40; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "frame-%03d.png", i);
    Write(root_ / "ref" / name, i, 0, &noise);
    Write(root_ / "query" / name, i, 20, &noise);
  }
  ImageSequenceEvaluationOptions options;
  options.reference_folder = (root_ / "ref").string();
  options.query_folder = (root_ / "query").string();
  options.frame_tolerance = 0;
  dataset::FileImageLoader loader;
  StatusOr<ImageSequenceEvaluation> e = EvaluateImageSequences(options, &loader, {}, nullptr);
  ASSERT_TRUE(e.ok()) << e.status().message();
  EXPECT_TRUE(IsImageSequenceFolder(options.query_folder));
  EXPECT_EQ(e->sequence_metrics.queries, 40u);
  EXPECT_DOUBLE_EQ(e->single_metrics.recall_at_1, 1.0);
  // A sequence is full from the tenth query on; from there every answer is exact.
  for (size_t q = 9; q < e->sequence.size(); ++q) EXPECT_EQ(e->sequence[q].match.reference, int(q));
  EXPECT_EQ(e->blank_references, 0u);
  // Centred, each query is placed with the frames after it too, the last ones by the route's last
  // sequence: every answer is exact, the first nine and the last four included.
  options.matcher.centred = true;
  StatusOr<ImageSequenceEvaluation> centred = EvaluateImageSequences(options, &loader, {}, nullptr);
  ASSERT_TRUE(centred.ok()) << centred.status().message();
  ASSERT_EQ(centred->sequence.size(), 40u);
  for (size_t q = 0; q < 40; ++q) EXPECT_EQ(centred->sequence[q].match.reference, int(q)) << q;
  options.matcher.centred = false;

  std::ofstream(root_ / "query" / "frame-020.png") << "not a PNG";
  e = EvaluateImageSequences(options, &loader, {}, nullptr);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.status().message().find("frame-020.png"), std::string::npos) << e.status().message();
}

// Descriptors from files are matched by themselves: query i's descriptor is
// reference (i + 7) % 40's, while its image is reference i's, so the descriptor answers are
// i + 7 (single frames all, sequences wherever the line does not wrap round the route) and the
// image answers stay i. Bad files are errors naming the file: a missing one, one without the
// other, a row count that is not the image count, an all-zero row, two lengths.
TEST_F(ImageFoldersTest, DescriptorFilesAreMatchedBesideTheImages) {
  Random noise(4);
  const int n = 40, shift = 7, dims = 16;
  dataset::DescriptorMatrix refs{size_t(n), size_t(dims), {}}, queries{size_t(n), size_t(dims), {}};
  Random draw(5);
  for (int i = 0; i < n; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "frame-%03d.png", i);
    Write(root_ / "ref" / name, i, 0, &noise);
    Write(root_ / "query" / name, i, 20, &noise);
    for (int k = 0; k < dims; ++k) refs.values.push_back(static_cast<float>(draw.Gaussian(0, 1)));
  }
  for (int i = 0; i < n; ++i) {
    const float* row = refs.values.data() + size_t((i + shift) % n) * dims;
    // Scaled and slightly disturbed: cosine similarity ignores the scale.
    for (int k = 0; k < dims; ++k) {
      queries.values.push_back(3.0f * row[k] + static_cast<float>(draw.Gaussian(0, 0.05)));
    }
  }
  ASSERT_TRUE(dataset::WriteDescriptorNpy(refs, (root_ / "ref" / "d.npy").string()).ok());
  ASSERT_TRUE(dataset::WriteDescriptorNpy(queries, (root_ / "query" / "d.npy").string()).ok());
  ImageSequenceEvaluationOptions options;
  options.reference_folder = (root_ / "ref").string();
  options.query_folder = (root_ / "query").string();
  options.frame_tolerance = 0;
  options.reference_descriptors = (root_ / "ref" / "d.npy").string();
  options.query_descriptors = (root_ / "query" / "d.npy").string();
  dataset::FileImageLoader loader;
  StatusOr<ImageSequenceEvaluation> e = EvaluateImageSequences(options, &loader, {}, nullptr);
  ASSERT_TRUE(e.ok()) << e.status().message();
  ASSERT_TRUE(e->descriptors.has_value());
  EXPECT_EQ(e->descriptor_dimensions, size_t(dims));
  EXPECT_DOUBLE_EQ(e->single_metrics.recall_at_1, 1.0);
  EXPECT_DOUBLE_EQ(e->descriptors->single_metrics.recall_at_1, 0.0);
  for (int q = 0; q < n; ++q) {
    EXPECT_EQ(e->descriptors->single[q].match.reference, (q + shift) % n) << q;
  }
  for (int q = 9; q + shift < n; ++q) {
    EXPECT_EQ(e->descriptors->sequence[q].match.reference, q + shift) << q;
  }

  auto error_of = [&](const ImageSequenceEvaluationOptions& o) {
    StatusOr<ImageSequenceEvaluation> bad = EvaluateImageSequences(o, &loader, {}, nullptr);
    return bad.ok() ? std::string("ok") : bad.status().message();
  };
  ImageSequenceEvaluationOptions missing = options;
  missing.query_descriptors = (root_ / "none.npy").string();
  EXPECT_NE(error_of(missing).find(missing.query_descriptors), std::string::npos)
      << error_of(missing);
  missing.query_descriptors.clear();
  EXPECT_NE(error_of(missing).find("one for the queries"), std::string::npos) << error_of(missing);
  dataset::DescriptorMatrix short_rows = queries;
  short_rows.rows = n - 1;
  short_rows.values.resize(size_t(n - 1) * dims);
  ASSERT_TRUE(dataset::WriteDescriptorNpy(short_rows, (root_ / "query" / "d.npy").string()).ok());
  EXPECT_NE(error_of(options).find("d.npy: 39 rows for the 40 images"), std::string::npos)
      << error_of(options);
  dataset::DescriptorMatrix zero = queries;
  std::fill(zero.values.begin() + 2 * dims, zero.values.begin() + 3 * dims, 0.0f);
  ASSERT_TRUE(dataset::WriteDescriptorNpy(zero, (root_ / "query" / "d.npy").string()).ok());
  EXPECT_NE(error_of(options).find("d.npy: row 3 has no direction"), std::string::npos)
      << error_of(options);
  dataset::DescriptorMatrix narrow{size_t(n), 4, std::vector<float>(size_t(n) * 4, 1.0f)};
  ASSERT_TRUE(dataset::WriteDescriptorNpy(narrow, (root_ / "query" / "d.npy").string()).ok());
  EXPECT_NE(error_of(options).find("4 values per row"), std::string::npos) << error_of(options);
}

// Visual FABMAP as a matcher of single frames: 30 places of 128x96 images of random rectangles
// (corners for ORB), the queries the same scenes with noise. With a vocabulary learnt from the
// references, far more than chance (1 in 30) of the queries land on their own place, and the
// answers and metrics are where the other matchers' are. A visual model file that does not
// exist is an error naming it.
TEST_F(ImageFoldersTest, FabmapPlacesSingleFramesFromVisualWords) {
  Random noise(3);
  const int n = 30;
  for (int i = 0; i < n; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "frame-%03d.png", i);
    Random scene(500 + i);
    cv::Mat image(96, 128, CV_8UC1, cv::Scalar(128));
    for (int k = 0; k < 25; ++k) {
      const int x = static_cast<int>(scene.Uniform(0, 110)),
                y = static_cast<int>(scene.Uniform(0, 80));
      const int w = static_cast<int>(scene.Uniform(6, 30)),
                h = static_cast<int>(scene.Uniform(6, 30));
      cv::rectangle(image, cv::Rect(x, y, w, h), cv::Scalar(scene.Uniform(0, 255)), cv::FILLED);
    }
    ASSERT_TRUE(cv::imwrite((root_ / "ref" / name).string(), image));
    cv::Mat query = image.clone();
    for (int y = 0; y < query.rows; ++y) {
      for (int x = 0; x < query.cols; ++x) {
        query.at<uint8_t>(y, x) =
            cv::saturate_cast<uint8_t>(query.at<uint8_t>(y, x) + noise.Gaussian(0, 4));
      }
    }
    ASSERT_TRUE(cv::imwrite((root_ / "query" / name).string(), query));
  }
  ImageSequenceEvaluationOptions options;
  options.reference_folder = (root_ / "ref").string();
  options.query_folder = (root_ / "query").string();
  options.frame_tolerance = 0;
  options.matcher.image_width_px = 64;
  options.matcher.image_height_px = 32;
  options.fabmap = true;
  options.fabmap_settings.vocabulary.words = 200;
  options.fabmap_settings.visual_model.training_image_step = 1;
  dataset::FileImageLoader loader;
  StatusOr<ImageSequenceEvaluation> e = EvaluateImageSequences(options, &loader, {}, nullptr);
  ASSERT_TRUE(e.ok()) << e.status().message();
  ASSERT_TRUE(e->fabmap.has_value());
  EXPECT_EQ(e->fabmap->vocabulary, 200u);
  EXPECT_TRUE(e->fabmap->trained_here);
  EXPECT_GT(e->fabmap->words_per_query, 5.0);
  ASSERT_EQ(e->fabmap->answers.size(), size_t(n));
  EXPECT_EQ(e->fabmap->metrics.queries, size_t(n));
  EXPECT_GE(e->fabmap->metrics.recall_at_1, 0.8);  // all 30 here; chance 1 in 30
  EXPECT_GE(e->fabmap->metrics.recall_at_5, e->fabmap->metrics.recall_at_1);
  for (const QueryAnswer& a : e->fabmap->answers) {
    ASSERT_FALSE(a.match.declined);
    EXPECT_TRUE(std::isfinite(a.match.confidence));
  }

  options.fabmap_settings.visual_model.file = (root_ / "missing.bin").string();
  e = EvaluateImageSequences(options, &loader, {}, nullptr);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.status().message().find("missing.bin"), std::string::npos) << e.status().message();
}

}  // namespace
}  // namespace ratslam::session
