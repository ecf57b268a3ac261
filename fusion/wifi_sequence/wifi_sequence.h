// Wi-Fi pose-sequence loop closure (Kudo and Miura, "Utilizing WiFi Signals for Improving SLAM
// and Person Localization", section III; equation numbers are that paper's).
//
// Poses are Wi-Fi scans: each scan is recorded with the travel, the dead-reckoned pose and the
// caller's anchor (the experience current at the scan and the scan's pose relative to it). A
// sequence of scans revisiting a place (the current sequence, CS) is matched against the past
// scans that resemble it (the past sequence, PS) by continuous DP over the smoothed Wi-Fi
// similarity; the correspondences are verified by the shape of the two dead-reckoned sequences
// (the paper uses laser ICP; we have no laser) and the inliers become links.
//
// Three parts, each usable alone:
//  - SmoothedSignalMatrix: the signal-pose matrix S, smoothed over travel (eqs. 1-4), sparse,
//    updated per new pose; cosine similarity between poses.
//  - ContinuousDpMatch: spots a CS inside a longer PS (eq. 5) with uncrossed correspondences.
//  - VerifyCorrespondences: exhaustive pair hypotheses, least-squares rigid fit and a
//    statistical outlier test (fig. 7) on the odometry positions.
// WifiSequenceLoopCloser strings them together online.
#ifndef RATSLAM_FUSION_WIFI_SEQUENCE_WIFI_SEQUENCE_H_
#define RATSLAM_FUSION_WIFI_SEQUENCE_WIFI_SEQUENCE_H_

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/geometry.h"
#include "common/schema.h"
#include "common/sensor_samples.h"
#include "common/status.h"

namespace ratslam::wifi_sequence {

struct WifiSequenceOptions {
  bool enabled = false;  // run sequence loop closure beside the front end

  // Similarity (section III-B.2).
  double smoothing_tau_m = 1.5;       // tau of eq. 3
  double smoothing_cutoff_tau = 4.0;  // weights beyond this many tau of travel are left out
  double min_rssi_dbm = -100.0;       // eq. 1's zero: SQ = 2 (RSSI - this), clamped to [0, 100]

  // Loop candidates from pose uncertainty (section III-B.1, III-B.3). A past pose i is a
  // candidate for the current pose t when the map puts t inside i's confidence circle of radius
  // confidence_sigmas * sigma, with sigma^2 = position_sigma^2 + distance_noise * D +
  // heading_noise * D^3 / 3 for the travel D between them (odometry with a per-metre distance
  // variance and a heading random walk; the cube is the lateral error the heading walk makes),
  // sigma capped at max_sigma_m.
  double position_sigma_m = 1.0;           // uncertainty of a pose right after the past one
  double distance_noise_m2_per_m = 0.01;   // distance variance per metre of travel
  double heading_noise_rad2_per_m = 3e-6;  // heading variance per metre of travel
  double max_sigma_m = 5.0;                // cap: beyond it Wi-Fi similarity decides alone
  double confidence_sigmas = 3.0;          // the paper's 3-sigma ellipse
  double min_loop_travel_m = 30.0;         // a past pose must be this much travel behind
  int min_sequence_poses = 5;              // shorter CS (after trimming) or PS: no loop
  int max_sequence_poses = 30;             // a CS this long is matched, and a new one starts

  // Past sequence and DP (section III-B.3, III-C.1).
  double past_similarity = 0.8;  // PS: least similarity to some CS pose
  double past_split_m = 15.0;    // PS poses further apart in travel are separate past visits
  bool match_reversed = false;   // also spot the CS in each past visit walked the other way
  double dp_alpha = 1.1;         // eq. 5's weight of non-diagonal steps
  double min_similarity = 0.01;  // cost = 1 / max(similarity, this)

  // Verification (section III-C.2, fig. 7) on dead-reckoned positions.
  double pair_min_separation_m = 3.0;  // the two correspondences of a hypothesis: this far apart
  double inlier_distance_m = 3.0;      // residual that agrees with a hypothesis
  double outlier_sigmas = 3.0;         // statistical test: residual above this many sigma drops
  double residual_floor_m = 0.5;       // least sigma of that test (dead reckoning is not exact)
  double max_compass_disagreement_rad = 0.5;  // fit rotation against the compass (if known)
  int min_inliers = 5;                        // a loop needs this many verified correspondences
  double min_inlier_fraction = 0.5;           // and this share of the CS

  bool IsValid(std::string* error) const;

  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("enabled", enabled,
      "close loops by Wi-Fi pose-sequence matching (Kudo and Miura) beside the front end",
      schema::Any());
    v("smoothing_tau_m", smoothing_tau_m,
      "tau of eq. 3: Gaussian smoothing of each AP's signal over cumulative travel",
      schema::Unit("m").Positive());
    v("smoothing_cutoff_tau", smoothing_cutoff_tau,
      "smoothing weights beyond this many tau of travel are left out (4: below e^-8)",
      schema::Unit("tau").Within(1, 10));
    v("min_rssi_dbm", min_rssi_dbm,
      "zero of eq. 1's signal quality SQ = 2 (RSSI - this), clamped to [0, 100]",
      schema::Unit("dBm").Within(-200, 0));
    v("position_sigma_m", position_sigma_m,
      "pose uncertainty right after a past pose (the confidence circle's least sigma)",
      schema::Unit("m").Positive());
    v("distance_noise_m2_per_m", distance_noise_m2_per_m,
      "odometry distance variance per metre of travel", schema::Unit("m^2/m").NonNegative());
    v("heading_noise_rad2_per_m", heading_noise_rad2_per_m,
      "odometry heading variance per metre of travel (lateral error grows as D^3 / 3)",
      schema::Unit("rad^2/m").NonNegative());
    v("max_sigma_m", max_sigma_m, "cap on that sigma: further apart, Wi-Fi similarity decides",
      schema::Unit("m").Positive());
    v("confidence_sigmas", confidence_sigmas,
      "radius of the confidence circle in sigmas (the paper's 3-sigma ellipse)",
      schema::Unit("sigmas").Positive());
    v("min_loop_travel_m", min_loop_travel_m,
      "a past pose is a loop candidate only this much travel behind the current one",
      schema::Unit("m").Positive());
    v("min_sequence_poses", min_sequence_poses,
      "a current sequence (after trimming) or past sequence shorter than this is no loop",
      schema::Unit("poses").AtLeast(2));
    v("max_sequence_poses", max_sequence_poses,
      "a current sequence this long is matched at once and a new one starts",
      schema::Unit("poses").AtLeast(2));
    v("past_similarity", past_similarity,
      "past sequence: poses at least this similar (cosine) to some pose of the current one",
      schema::Unit("").Within(0, 1));
    v("past_split_m", past_split_m,
      "past sequence: a travel gap above this between PS poses starts another past visit, "
      "spotted by its own DP",
      schema::Unit("m").Positive());
    v("match_reversed", match_reversed,
      "also match each past visit backwards: a corridor walked the other way (the DP then pairs "
      "the current sequence with the visit in reverse order)",
      schema::Any());
    v("dp_alpha", dp_alpha, "alpha of eq. 5: cost weight of a non-diagonal DP step",
      schema::Unit("").AtLeast(1));
    v("min_similarity", min_similarity,
      "DP cell cost is 1 / max(similarity, this), so dissimilar poses cost 1 / this",
      schema::Unit("").Within(1e-6, 1));
    v("pair_min_separation_m", pair_min_separation_m,
      "verification: the two correspondences of a hypothesis are at least this far apart",
      schema::Unit("m").Positive());
    v("inlier_distance_m", inlier_distance_m,
      "verification: a correspondence agrees with a hypothesis within this residual",
      schema::Unit("m").Positive());
    v("outlier_sigmas", outlier_sigmas,
      "verification: residuals above this many (median-based) sigmas are outliers",
      schema::Unit("sigmas").Positive());
    v("residual_floor_m", residual_floor_m, "verification: least sigma of the outlier test",
      schema::Unit("m").Positive());
    v("max_compass_disagreement_rad", max_compass_disagreement_rad,
      "verification, when every pose has a compass heading: the fit's rotation must agree with "
      "the rotation the compass gives between the two sequences' odometry frames within this",
      schema::Unit("rad").Within(0, 3.2));
    v("min_inliers", min_inliers, "a loop needs at least this many verified correspondences",
      schema::Unit("correspondences").AtLeast(2));
    v("min_inlier_fraction", min_inlier_fraction, "and at least this share of the current sequence",
      schema::Unit("").Within(0, 1));
  }
};

// A sparse vector: (AP index, value), ascending AP index.
using SparseSignal = std::vector<std::pair<uint32_t, double>>;

// Eq. 1: signal quality of a reading, 0 for an AP not heard.
double SignalQuality(double rssi_dbm, double min_rssi_dbm);

// The smoothed signal-pose matrix SA (eqs. 2-4). Row t is sum_i w(t, i) s_i / sum_i w(t, i)
// with w = exp(-D^2 / (2 tau^2)) over the travel D between poses t and i, for |D| within the
// cutoff. Adding a pose updates only the rows within the cutoff, in a fixed order, so the same
// poses added in the same order give the same matrix bit for bit.
class SmoothedSignalMatrix {
 public:
  SmoothedSignalMatrix(double tau_m, double cutoff_tau);

  // Appends a pose with travel `travel_m` (not below the previous pose's) and raw signal `s`.
  void Add(double travel_m, SparseSignal s);

  size_t size() const { return raw_.size(); }
  // Row t of SA, normalised so that its weights sum to one (eq. 4).
  SparseSignal Smoothed(size_t t) const;
  // Smoothing weights of row t, normalised (eq. 3-4): (pose, weight), ascending pose.
  std::vector<std::pair<size_t, double>> Weights(size_t t) const;
  // Cosine similarity of rows i and j of SA (0 when either is all zero).
  double Similarity(size_t i, size_t j) const;
  // Row t before normalisation (the same direction as Smoothed(t)) and its Euclidean norm.
  const SparseSignal& Unnormalised(size_t t) const { return sum_[t]; }
  double Norm(size_t t) const;
  const SparseSignal& Raw(size_t t) const { return raw_[t]; }
  double Travel(size_t t) const { return travel_[t]; }

 private:
  double Weight(double distance_m) const;
  double tau_m_, cutoff_m_;
  std::vector<double> travel_;
  std::vector<SparseSignal> raw_;
  std::vector<SparseSignal> sum_;     // unnormalised sum_i w s_i
  std::vector<double> weight_sum_;    // sum_i w
  mutable std::vector<double> norm_;  // |sum_| per row; negative: stale
  SparseSignal scratch_;              // merge buffer (no state)
};

// One pair of the DP path: row `current` of the CS matched to column `past` of the PS.
struct DpCorrespondence {
  uint32_t current = 0;
  uint32_t past = 0;
};

struct DpMatch {
  double cost = 0.0;  // g of the path's last cell (eq. 5)
  // One per CS row in ascending order, past non-decreasing (never crossing): of the path's
  // cells in a row, the cheapest.
  std::vector<DpCorrespondence> pairs;
};

// Continuous DP (eq. 5): the cheapest path from any cell of the first row to any cell of the
// last row of `cost` (rows: CS, columns: PS, row-major, rows x cols), with slopes between 1/3
// and 3. Fails on an empty matrix or a non-finite cost; one row or column is a path too.
StatusOr<DpMatch> ContinuousDpMatch(const std::vector<double>& cost, size_t rows, size_t cols,
                                    double alpha);

struct Verification {
  std::vector<bool> inlier;  // per correspondence
  size_t inliers = 0;
  RigidAlignment2D transform;      // current positions onto past ones, fitted on the inliers
  std::vector<double> residual_m;  // per correspondence, under `transform`
};

// Fig. 7's mismatch exclusion on positions: every pair of correspondences (far enough apart)
// proposes the rigid transform that superposes them; the one most others agree with (within
// inlier_distance_m) wins; then a least-squares fit on its inliers and a statistical test
// (residual > outlier_sigmas * max(1.4826 * median residual, residual_floor_m) drops) repeat
// until nothing changes. `current[k]` and `past[k]` are a correspondence.
Verification VerifyCorrespondences(const std::vector<Point2>& current,
                                   const std::vector<Point2>& past,
                                   const WifiSequenceOptions& options);

// A pose's raw signal as saved: eq. 1's signal quality per AP heard, ascending AP index.
struct PoseSignal {
  std::vector<uint32_t> aps;
  std::vector<double> quality;
};

// A pose of the loop closer: one Wi-Fi scan.
struct SequencePose {
  double time_s = 0.0;
  double travel_m = 0.0;  // cumulative odometric travel
  Pose2 odometry;         // dead-reckoned pose
  int64_t anchor = -1;    // the caller's anchor (the current experience), -1 for none
  Pose2 anchor_offset;    // this pose in the anchor's frame
  std::optional<double> compass_heading_rad;  // absolute heading at the scan, if known
};

struct SequenceCorrespondence {
  uint32_t current_pose = 0;
  uint32_t past_pose = 0;
  double similarity = 0.0;
  bool inlier = false;
  double residual_m = 0.0;
};

struct SequenceLoop {
  uint32_t id = 0;
  double time_s = 0.0;                                  // when it was matched
  std::vector<uint32_t> current_sequence;               // CS pose indices after trimming
  std::vector<uint32_t> past_sequence;                  // PS pose indices
  std::vector<SequenceCorrespondence> correspondences;  // the DP path, one per CS pose
  Pose2 transform;  // maps the CS's dead-reckoned poses onto the PS's (verified fit)
  double dp_cost = 0.0;
  uint32_t inliers = 0;
  bool reversed = false;  // matched against a past visit walked the other way
  bool accepted = false;
  std::string outcome;  // "accepted" or why not
};

// The start of an accepted loop's outcome when none of its links reached the experience map
// (the front end had joined those places already).
inline constexpr char kNoLinkOutcome[] = "accepted; no link made";

class WifiSequenceLoopCloser {
 public:
  struct State {
    std::vector<std::string> bssids;  // AP index -> BSSID
    std::vector<SequencePose> poses;
    std::vector<PoseSignal> signals;      // per pose
    std::vector<uint32_t> open_sequence;  // the CS being built (untrimmed)
    bool open_continues = false;          // it continues one cut at max_sequence_poses
    double open_start_radius_m = 0.0;     // its first confidence radius
    double open_end_radius_m = 0.0;       // its latest confidence radius
    std::vector<SequenceLoop> loops;
  };

  // `options` must be valid; throws std::invalid_argument otherwise.
  explicit WifiSequenceLoopCloser(const WifiSequenceOptions& options);

  // Adds scan `scan` as a new pose. `map_positions` holds the map's current estimate of every
  // pose, this one last (size() + 1 entries): the candidate test uses it. Returns the loop
  // matched at this pose, if a current sequence ended here (accepted or not; see `accepted`).
  // Fails, changing nothing, on a travel that goes back, a non-finite value or a wrong count.
  StatusOr<std::optional<SequenceLoop>> AddPose(const SequencePose& pose, const WifiScan& scan,
                                                const std::vector<Point2>& map_positions);
  // Matches the open current sequence now (the end of a run). Returns the loop, if any.
  std::optional<SequenceLoop> Flush(double time_s);

  size_t size() const { return state_.poses.size(); }
  const SequencePose& pose(size_t i) const { return state_.poses[i]; }
  const std::vector<SequenceLoop>& loops() const { return state_.loops; }
  // Replaces loop `id`'s outcome (what became of an accepted loop's links: kNoLinkOutcome
  // first when none reached the map); unknown ids are ignored.
  void SetOutcome(uint32_t id, std::string outcome) {
    for (SequenceLoop& l : state_.loops) {
      if (l.id == id) l.outcome = std::move(outcome);
    }
  }
  const SmoothedSignalMatrix& similarity() const { return matrix_; }
  const WifiSequenceOptions& options() const { return options_; }
  const State& state() const { return state_; }
  // Restores a state (rebuilding the smoothed matrix); all or nothing.
  Status SetState(State state);

  // The relative pose of past pose `past` to current pose `current` implied by a loop's
  // transform: where the current pose is, seen from the past one.
  Pose2 RelativePose(const SequenceLoop& loop, uint32_t current, uint32_t past) const;

 private:
  // Matches the open sequence (`ended`: it ended by leaving the past poses' circles, so its
  // last confidence circle is trimmed) and records the loop; none for a too short sequence.
  std::optional<SequenceLoop> Match(double time_s, bool ended);
  double Sigma(double travel_m) const;
  // True unless every verified pose has a compass heading and the fit's rotation disagrees.
  bool CompassAgrees(const std::vector<SequenceCorrespondence>& pairs, const Verification& v) const;

  WifiSequenceOptions options_;
  State state_;
  std::map<std::string, uint32_t> ap_index_;
  SmoothedSignalMatrix matrix_;
};

}  // namespace ratslam::wifi_sequence

#endif  // RATSLAM_FUSION_WIFI_SEQUENCE_WIFI_SEQUENCE_H_
