// `ratslam evaluate` on two image sequences of one route (a reference traverse and a query
// traverse, e.g. Nordland summer and winter): every query frame is placed on the reference route
// by the sequence matcher (sensors/sequence_matcher.h) and, as the baseline in the same run, by
// its single frame alone. A query is right when the answer lies within `frame_tolerance`
// reference frames of its true place; a declined query (a blank frame) counts as wrong.
#ifndef RATSLAM_SESSION_IMAGE_SEQUENCE_EVALUATION_H_
#define RATSLAM_SESSION_IMAGE_SEQUENCE_EVALUATION_H_

#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/output_folder.h"
#include "common/provenance.h"
#include "common/status.h"
#include "dataset/image_loader.h"
#include "fusion/fabmap_front_end_options.h"
#include "sensors/sequence_matcher.h"

namespace ratslam::session {

// A folder that holds images (and no replay manifest): what `evaluate` reads as an image
// sequence.
bool IsImageSequenceFolder(const std::string& path);

// The folder's image files (png, jpg, jpeg, pgm, ppm, bmp, tif, tiff), sorted by name (route
// order for zero-padded frame numbers).
StatusOr<std::vector<std::string>> ListImageSequence(const std::string& folder);

// The true reference of each query (-1: none known): from `ground_truth_csv` (columns `query`,
// `reference`: file names in the two folders) when given; else by equal file names when every
// query's name is a reference's; else by position when both hold as many files.
StatusOr<std::vector<int>> PairQueriesWithReferences(const std::vector<std::string>& references,
                                                     const std::vector<std::string>& queries,
                                                     const std::string& ground_truth_csv);

struct QueryAnswer {
  int truth = -1;  // true reference, -1 when not known
  sensors::SequenceMatch match;
};

struct PrecisionRecall {
  double recall = 0.0, precision = 0.0, threshold = 0.0;
};

struct PlaceRecognitionMetrics {
  size_t queries = 0;        // with a known true place
  size_t declined = 0;       // of those
  double recall_at_1 = 0.0;  // best answer within the tolerance; declined counts as wrong
  double recall_at_5 = 0.0;  // one of the best five within the tolerance
  // Queries accepted by decreasing confidence: precision = right / accepted, recall = right /
  // queries; area under that curve (average precision) and the recall while precision is 1.
  double pr_auc = 0.0;
  double recall_at_100_precision = 0.0;
  std::vector<PrecisionRecall> curve;  // from the most confident down, one point per tie group
};

PlaceRecognitionMetrics MetricsOf(const std::vector<QueryAnswer>& answers, int frame_tolerance);

struct ImageSequenceEvaluationOptions {
  std::string reference_folder;
  std::string query_folder;
  std::string ground_truth_csv;  // optional
  int frame_tolerance = 1;
  sensors::SequenceMatcherOptions matcher;
  // Place descriptors computed elsewhere (NetVLAD, a ViT, ...; formats in
  // dataset/descriptor_file.h), one row per image of its folder in file-name order. Both or
  // neither: given, they are matched too, by single frames and by sequences over 1 - cosine
  // similarity, beside the images (blank images stay blank).
  std::string reference_descriptors, query_descriptors;
  // FABMAP over visual words (fusion/fabmap, vision alone) as another single-frame matcher: every
  // reference image a place, each query placed by the most probable one, its confidence the log
  // odds of that place against the new place. The vocabulary, tree and unknown world come from
  // `fabmap_settings.visual_model` (a saved model or training images), else are trained on the
  // reference images.
  bool fabmap = false;
  fusion::FabmapSettings fabmap_settings;
};

// One matcher's answers and their metrics: by sequences and by single frames.
struct MatcherAnswers {
  std::vector<QueryAnswer> sequence, single;  // per query
  PlaceRecognitionMetrics sequence_metrics, single_metrics;
};

struct ImageSequenceEvaluation {
  std::vector<std::string> reference_files, query_files;  // names inside their folders
  std::vector<int> truth;                                 // per query
  std::vector<QueryAnswer> sequence, single;              // per query
  size_t blank_references = 0, blank_queries = 0;
  std::vector<bool> reference_blank;  // per reference
  PlaceRecognitionMetrics sequence_metrics, single_metrics;
  // Every query's raw differences, for the difference-matrix figure (queries x references).
  std::vector<std::vector<float>> differences;
  double load_seconds = 0.0, match_seconds = 0.0;
  // With descriptor files: the descriptors' answers, their length and matching time.
  std::optional<MatcherAnswers> descriptors;
  size_t descriptor_dimensions = 0;
  double descriptor_match_seconds = 0.0;
  // With fabmap: its answers (per query) and metrics, the vocabulary's size, the mean number of
  // distinct words per reference and per query image, whether the model was trained here, and
  // the time of training, words and localisation.
  struct Fabmap {
    std::vector<QueryAnswer> answers;
    PlaceRecognitionMetrics metrics;
    size_t vocabulary = 0;
    double words_per_reference = 0.0, words_per_query = 0.0;
    bool trained_here = false;
    double seconds = 0.0;
  };
  std::optional<Fabmap> fabmap;
};

// Loads both folders and places every query. `progress` (may be empty) is called with queries
// done and total; `stop` (may be null) is checked between queries.
StatusOr<ImageSequenceEvaluation> EvaluateImageSequences(
    const ImageSequenceEvaluationOptions& options, ImageLoader* loader,
    const std::function<void(size_t, size_t)>& progress, const std::atomic<bool>* stop);

// evaluation.json (the metrics of both, the inputs, `run`) and queries.csv (a row per query).
Status WriteImageSequenceOutputs(const ImageSequenceEvaluationOptions& options,
                                 const ImageSequenceEvaluation& evaluation,
                                 const std::string& config_toml, uint64_t config_fingerprint,
                                 const RunProvenance& provenance, OutputFolder* out);

}  // namespace ratslam::session

#endif  // RATSLAM_SESSION_IMAGE_SEQUENCE_EVALUATION_H_
