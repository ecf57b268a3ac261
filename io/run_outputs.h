// What a replay writes beside its outputs: experiences and links (CSV), the trajectory in TUM
// format, the experience graph in g2o format, and summary.json with counts, speed and, when the
// data set has ground truth, absolute trajectory errors after rigid alignment.
#ifndef RATSLAM_IO_RUN_OUTPUTS_H_
#define RATSLAM_IO_RUN_OUTPUTS_H_

#include <optional>
#include <string>

#include "common/geometry.h"
#include "common/output_folder.h"
#include "common/provenance.h"
#include "common/status.h"
#include "fusion/replay_pipeline.h"

namespace ratslam::io {

struct RunInfo {
  double wall_seconds = 0.0;  // of this process's replay (not of earlier resumed parts)
  // Of its calibration pass ([fabmap_front_end] calibrate_earlier_session_log_odds), if any.
  std::optional<double> calibration_wall_seconds;
  uint64_t frames_this_run = 0;  // view frames processed by this process
  bool interrupted = false;      // stopped by a signal
  std::string config_path;       // as given, or empty for built-in defaults
  uint64_t config_fingerprint = 0;
  std::string resumed_from;         // map file, or empty
  std::string localised_on;         // map file of a localisation run (replay --localise)
  double lost_after_m = 0.0;        // its lost distance
  RunProvenance provenance;         // command line and start time, for summary.json's `run`
  std::vector<std::string> inputs;  // the data paths, as given
};

struct RunSummary {
  uint64_t frames = 0, templates = 0, experiences = 0, links = 0, loop_closures = 0;
  std::optional<double> map_ate_m, trajectory_ate_m, odometry_ate_m;
  size_t ate_points = 0;
  // Template matches with ground truth at both ends: now, and where the template was stored.
  size_t evaluated_matches = 0;
  std::vector<double> match_distances_m;
  size_t floor_mistakes = 0;
  // Matches with an end between ground-truth points on different floors (counted never within).
  size_t floor_unverified_matches = 0;
  // Of them, matches to a template stored in another session (multi-session runs): with a
  // session per phone, the cross-device matches.
  std::vector<double> cross_session_distances_m;
  // Localisation runs: per view frame of localisation(), the error of the aligned position
  // (NaN when lost or without ground truth); see LocalisationErrors.
  std::vector<double> localisation_errors_m;
  std::optional<double> localisation_median_error_m;
  std::optional<double> lost_fraction;  // present for localisation runs only
  std::string json;                     // the whole summary.json text
};

// The corrected pose of a trajectory record in the final map.
void RecordPose(const ExperienceMap& map, const TrajectoryRecord& record, double* x_m, double* y_m,
                double* theta_rad);

// A localisation run's error per record: the positions of the frames not lost are rigidly aligned
// to the ground truth at their times (least squares, as for the ATE: the frozen map's frame is
// not the ground truth's), and each error is the aligned position's distance from the truth. NaN
// for a lost frame, a frame outside the ground truth, or when fewer than 10 frames can be aligned
// (a fit to fewer would fit them almost exactly, whatever they are).
// `truth` (optional) gets the true position, NaN where none. With `session_starts` nothing is
// interpolated between two sessions (GroundTruthAt).
// Cross-session place recognition scored by image file names: in data sets whose sessions
// photograph the same places under the same names (Nordland's seasons), a frame of a later
// session that ends on a template made in an earlier session is correct within N frames when the
// template's first frame is at most N images from the frame's namesake in that session.
struct CrossSessionPlaces {
  size_t frames = 0;   // images of later sessions whose name an earlier session has (with a
                       // view or without: a frame without one is not matched)
  size_t matched = 0;  // of them, frames on a template made in an earlier session
  // Of the matched, those correct within each tolerance of kPlaceTolerancesFrames.
  std::vector<size_t> correct;
};
inline constexpr int kPlaceTolerancesFrames[] = {0, 1, 2, 5};
// Frames pair with images by time. Nothing (frames == 0) when the data set has one session or
// no name recurs.
CrossSessionPlaces ScoreCrossSessionPlaces(const std::vector<FrameRecord>& frames,
                                           const dataset::Dataset& dataset);

std::vector<double> LocalisationErrors(const std::vector<LocalisationRecord>& records,
                                       const std::vector<GroundTruthRow>& ground_truth,
                                       std::vector<Point2>* truth = nullptr,
                                       const std::vector<double>& session_starts = {});

RunSummary Summarise(const fusion::ReplayPipeline& pipeline, const dataset::Dataset& dataset,
                     const RunInfo& info);

// Writes experiences.csv, links.csv, trajectory_tum.txt, odometry_tum.txt (and with ground truth
// ground_truth_tum.txt), experience_map.g2o,
// frames.csv and summary.json into `folder`, all of them or none (a failure keeps the earlier
// files and names the one that failed).
// Every top-level key summary.json can have (some only under some configurations): sweeps check
// their objective and metrics against it when planned. A test keeps it complete.
const std::vector<std::string>& SummaryKeys();

StatusOr<RunSummary> WriteRunOutputs(OutputFolder& folder, const fusion::ReplayPipeline& pipeline,
                                     const dataset::Dataset& dataset, const RunInfo& info);

}  // namespace ratslam::io

#endif  // RATSLAM_IO_RUN_OUTPUTS_H_
