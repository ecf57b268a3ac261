// The FABMAP localisation benchmark (`ratslam evaluate`) as a library session: Load the map and
// query places (splitting one data set when map and query are the same), Prepare the visual
// model, words and localiser, Localise every query, WriteOutputs (evaluation.json, queries.csv,
// config.toml and a trained visual_model.bin). Figures are the caller's (the viewer draws them
// from the result).
#ifndef RATSLAM_SESSION_EVALUATION_SESSION_H_
#define RATSLAM_SESSION_EVALUATION_SESSION_H_

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/clock.h"
#include "common/output_folder.h"
#include "common/progress.h"
#include "common/provenance.h"
#include "common/status.h"
#include "dataset/image_loader.h"
#include "fusion/fabmap/evaluation.h"
#include "fusion/fabmap/localiser.h"
#include "fusion/fabmap/visual_model.h"
#include "fusion/replay_pipeline.h"
#include "session/evaluation_nodes.h"

namespace ratslam::session {

struct EvaluationSessionOptions {
  fusion::PipelineOptions pipeline;  // [fabmap...] sections, [evaluation], and [pdr] for phone logs
  std::string config_path;           // as given, for evaluation.json
  std::string map_path;
  std::string query_path;    // may name the same data set as map_path: then it is split
  bool lenient = false;      // skip (and count) malformed lines of phone logs and CSVs
  RunProvenance provenance;  // command line and start time, for evaluation.json's `run`
};

struct EvaluationResult {
  std::vector<fabmap::EvaluationNode> map, queries;
  std::vector<int64_t> matches;  // per query: map index, or -1 for a new place (rejection)
  // Per query, the answer's position: the match's, or with [evaluation] answer = "posterior" the
  // vote of the most probable places (not located: a rejection).
  std::vector<fabmap::Estimate> answers;
  // Per query, FABMAP's posteriors: of the chosen hypothesis (the match, or the new place), of
  // the new place, and the best mapped place (-1: none) with its posterior.
  std::vector<double> match_probability, new_place_probability;
  std::vector<int64_t> best_mapped_place;
  std::vector<double> best_mapped_probability;
  std::vector<double> best_mapped_log_odds;  // LocalisationResult's: best mapped vs new place
  // Precision and recall of accepting the best mapped place above each posterior (pr_curve.csv).
  std::vector<fabmap::PrecisionRecallPoint> precision_recall;
  fabmap::EvaluationMetrics metrics;
  size_t wifi_words = 0, visual_words = 0;
  size_t wifi_map_scans = 0;   // map scans that define the Wi-Fi words
  size_t wifi_tree_scans = 0;  // of them, those that learnt the Wi-Fi Chow-Liu tree
  // With [evaluation] online_rssi_offset: per query session, the offset removed from its scans.
  std::vector<SessionRssiOffset> query_rssi_offsets;
  // The Wi-Fi baselines on the same map and queries (evaluation_baselines.h), by name ("knn",
  // "fingerprint"); empty when the map has no scan.
  std::vector<std::pair<std::string, fabmap::EvaluationMetrics>> baselines;
  // Floor classification (evaluation.json's floor_classification): the share of queries on a
  // floor the map holds, and by method (FABMAP's best mapped place, accepted or not; k-NN) the
  // share given their floor.
  double queries_on_mapped_floors = 0.0;
  std::vector<std::pair<std::string, double>> floor_accuracy;
  // With [evaluation] calibrate_new_place: the threshold learnt, the map's sessions and the folds
  // they were held out in (Localise then answers with the threshold).
  fabmap::NewPlaceThreshold new_place;
  size_t new_place_sessions = 0, new_place_folds = 0;
  double query_time_ms = 0.0;  // mean per query (FABMAP)
  double wall_time_s = 0.0;    // of the whole session so far
  std::string json;            // evaluation.json
};

// Every top-level key evaluation.json can have (some only in some modes): sweeps check their
// objective and metrics against it when planned. A test keeps it complete.
const std::vector<std::string>& EvaluationKeys();

class EvaluationSession {
 public:
  // `out` is required; `clock`, `progress` and `images` may be null (system clock, silence,
  // images from files).
  EvaluationSession(EvaluationSessionOptions options, OutputFolder* out,
                    const Clock* clock = nullptr, ProgressSink* progress = nullptr,
                    ImageLoader* images = nullptr);
  ~EvaluationSession();

  Status Load();
  Status Prepare();
  Status Localise();
  Status WriteOutputs();
  // All four; the first error stops it.
  StatusOr<EvaluationResult> Run();

  const EvaluationResult& result() const { return result_; }
  // Checked between images and between queries: when set, the running stage stops with an
  // error and stopped() is true (nothing is written after it).
  void set_stop_flag(const std::atomic<bool>* stop_requested) { stop_requested_ = stop_requested; }
  bool stopped() const { return stop_requested_ != nullptr && stop_requested_->load(); }
  fabmap::FabmapMode mode() const;

 private:
  Status Words(const std::vector<fabmap::EvaluationNode>& nodes, const std::string& what,
               std::vector<fabmap::Observation>* words);
  // A localiser over the given map nodes (indices into result_.map), with the session's settings.
  StatusOr<std::unique_ptr<fabmap::Localiser>> BuildLocaliser(
      const std::vector<size_t>& map_nodes) const;
  Status CalibrateNewPlace();

  EvaluationSessionOptions options_;
  OutputFolder* out_;
  const Clock* clock_;
  const std::atomic<bool>* stop_requested_ = nullptr;
  ProgressSink* progress_;
  ImageLoader* images_;
  SteadyClock system_clock_;
  SilentProgress no_progress_;
  std::unique_ptr<ImageLoader> own_images_;
  double started_s_ = 0.0;
  std::optional<fabmap::TrainedVisualModel> visual_;
  bool trained_here_ = false;
  std::vector<fabmap::Observation> map_words_, query_words_;
  std::unique_ptr<fabmap::Localiser> localiser_;
  EvaluationResult result_;
};

}  // namespace ratslam::session

#endif  // RATSLAM_SESSION_EVALUATION_SESSION_H_
