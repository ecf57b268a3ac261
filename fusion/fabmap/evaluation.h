// The localisation benchmark of the fusion paper (sections 5.2-5.3): map with part of the data,
// query with the rest, take the arg-max place (eq. 5). The error of a query is the distance
// between its position and the matched place's, infinite when the floor differs; a new-place
// answer is a rejection. Reported: the rate of correct localisations within d and of misplaced
// ones beyond d (fractions of all queries), the rejection rate and the floor-mistake rate.
#ifndef RATSLAM_FUSION_FABMAP_EVALUATION_H_
#define RATSLAM_FUSION_FABMAP_EVALUATION_H_

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/schema.h"
#include "common/sensor_samples.h"
#include "common/status.h"

namespace ratslam::fabmap {

// A place of the benchmark: where it is and what was sensed there.
struct EvaluationNode {
  double x_m = 0.0, y_m = 0.0;
  int floor = 0;     // another building's floors are other floors (UJIIndoorLoc: 100 b + f)
  int building = 0;  // 0 where a data set has one building
  double time_s = 0.0;
  double travelled_m = 0.0;  // along its session (Wi-Fi tree spacing); NaN: not recorded
  int session = 0;
  std::string image;                             // image path, if any
  std::optional<std::vector<WifiReading>> wifi;  // scan, if any
};

// kFirstSession: the first session makes the map, every other one queries it. kPosition: the
// nodes at one position (floor, x, y) stay together, so every query stands where no map node
// does (UJIIndoorLoc's reference points: the queries of its validation file stand anywhere).
enum class SplitUnit { kNode, kSession, kFirstSession, kPosition };
std::string ToString(SplitUnit unit);
StatusOr<SplitUnit> SplitUnitFromString(const std::string& name);

// How calibrate_new_place picks its log-odds threshold from the held-out map nodes.
// kYouden: the threshold with the best Youden's J over near and far nodes. kNearRecall: the
// highest threshold that still accepts `new_place_near_recall` of the near nodes (far ones are
// only reported): it needs no far nodes, and keeps its promise where map and queries are alike
// (the same users), but accepts more far queries where they differ (docs/results/fabmap.md,
// new-place table).
enum class NewPlaceRule { kNearRecall, kYouden };
std::string ToString(NewPlaceRule rule);
StatusOr<NewPlaceRule> NewPlaceRuleFromString(const std::string& name);

// How a query's answer is read from FABMAP's posterior over the mapped places.
// kBestPlace: the arg-max place's position (eq. 5; the paper's protocol).
// kPosterior: the `answer_places` most probable mapped places, weighted by their posterior
// tempered by `answer_temperature` (weight exp((log p_i - log p_best) / T)), vote for a building,
// then for a floor in it; the answer is their weighted mean position on that floor. The
// new-place decision is the same as kBestPlace's.
enum class AnswerRule { kBestPlace, kPosterior };
std::string ToString(AnswerRule rule);
StatusOr<AnswerRule> AnswerRuleFromString(const std::string& name);

struct EvaluationOptions {
  SplitUnit split =
      SplitUnit::kNode;          // when map and query are one data set: split by node or session
  double map_fraction = 0.4;     // share of nodes (or sessions) that make the map (paper: 40%)
  double frame_spacing_m = 0.5;  // image folders without positions: metres per frame
  double image_wifi_max_gap_s = 10.0;  // an image takes a scan at most this far in time
  double near_place_m = 5.0;           // a map place on the query's floor this close: "near"
  double far_place_m = 10.0;           // no map place on the query's floor this close: "far"
  bool calibrate_new_place = false;    // learn the new-place threshold from held-out map sessions
  int calibration_folds = 4;           // map sessions held out in this many interleaved groups
  NewPlaceRule new_place_rule = NewPlaceRule::kYouden;  // how the threshold is chosen
  double new_place_near_recall = 0.95;         // kNearRecall: share of near held-out nodes accepted
  AnswerRule answer = AnswerRule::kBestPlace;  // a query's position from FABMAP's posterior
  int answer_places = 5;                       // kPosterior: the most probable places that vote
  double answer_temperature = 10.0;            // kPosterior: posteriors tempered by this
  bool online_rssi_offset = false;             // remove each query session's RSSI offset, online
  int rssi_offset_min_common_aps = 5;          // APs a query shares with a map scan for an estimate
  int rssi_offset_min_estimates = 10;          // estimates before a session's offset is removed

  bool IsValid(std::string* error) const;
  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("split", split,
      "one data set for map and queries: split by node, session, first_session (map = the "
      "first session, queries = the others), or position (the nodes at one floor and position "
      "all on one side: every query stands where no map node does)",
      schema::Any());
    v("map_fraction", map_fraction, "share of nodes (or sessions) in the map; the rest query",
      schema::Unit("").Above(0).Below(1));
    v("frame_spacing_m", frame_spacing_m,
      "image folders have no positions: frame i is at i * this along its floor",
      schema::Unit("m").Positive());
    v("image_wifi_max_gap_s", image_wifi_max_gap_s,
      "an image is paired with a Wi-Fi scan at most this far in time",
      schema::Unit("s").NonNegative());
    v("near_place_m", near_place_m,
      "by_map_distance: queries with a map place on their floor at most this far are near (they "
      "should be located)",
      schema::Unit("m").Positive());
    v("far_place_m", far_place_m,
      "by_map_distance: queries with no map place on their floor this close are far (the map "
      "never saw them: they should be rejected); at least near_place_m",
      schema::Unit("m").Positive());
    v("calibrate_new_place", calibrate_new_place,
      "learn the new-place decision from the map: its sessions are held out in groups "
      "(calibration_folds), each localised against a map of the others, and a query is answered "
      "with its best mapped place only when that place's log odds against the new place exceed "
      "a threshold learnt from the held-out nodes near the rest of the map and far from it "
      "(new_place_rule; needs two map sessions)",
      schema::Any());
    v("calibration_folds", calibration_folds,
      "calibrate_new_place: map session k (in order of id) is held out with fold k mod this; "
      "more folds cost more localiser builds (at most one per session)",
      schema::Unit("").Within(2, 1000));
    v("new_place_rule", new_place_rule,
      "calibrate_new_place: youden (the best Youden's J over near and far held-out nodes) or "
      "near_recall (the highest threshold that accepts new_place_near_recall of the near "
      "held-out nodes)",
      schema::Any());
    v("new_place_near_recall", new_place_near_recall,
      "new_place_rule = near_recall: share of the held-out nodes near the rest of the map that "
      "the threshold accepts",
      schema::Unit("").Above(0).AtMost(1));
    v("answer", answer,
      "a query's answer from FABMAP's posterior: best_place (the arg-max place's position, the "
      "paper's protocol) or posterior (the answer_places most probable mapped places, weighted "
      "by their tempered posterior, vote for a building, then a floor in it; the answer is "
      "their weighted mean position on that floor); the new-place decision is the same",
      schema::Any());
    v("answer_places", answer_places, "answer = posterior: the most probable places that vote",
      schema::Unit("places").Within(1, 1000));
    v("answer_temperature", answer_temperature,
      "answer = posterior: a place's weight is exp((log p - log p_best) / this); FABMAP's "
      "posteriors are overconfident (the runner-up is often 1e-10 of the best or less), so 1 is "
      "nearly the arg-max and larger values let the runners-up count",
      schema::Unit("").AtLeast(1));
    v("online_rssi_offset", online_rssi_offset,
      "estimate each query session's RSSI offset to the map's scans from its own scans, in time "
      "order as a phone would online, and remove it once known (every method sees the "
      "corrected scans; phones that read several dB apart)",
      schema::Any());
    v("rssi_offset_min_common_aps", rssi_offset_min_common_aps,
      "APs a query scan must share with a map scan to estimate the offset",
      schema::Unit("APs").AtLeast(1));
    v("rssi_offset_min_estimates", rssi_offset_min_estimates,
      "offset estimates of a query session before its median is removed",
      schema::Unit("scans").AtLeast(1));
  }
};

// The new-place threshold learnt from labelled scores: `log_odds[i]` is a held-out node's best
// mapped place's log odds against the new place, `near[i]` whether that node was near the rest
// of the map (true) or far from it (false). A node is accepted when its log odds exceed t. The
// candidates are "accept every finite score" (t = -inf) and the midpoints between consecutive
// distinct scores. NaN counts as -inf (no mapped place, never accepted).
// kYouden: t maximises Youden's J, the share of near nodes accepted plus the share of far ones
// rejected (<= t), minus 1; ties go to the lowest t (accept more); needs both kinds of node.
// kNearRecall: the highest candidate that rejects at most floor((1 - near_recall) n) of the n
// near nodes (a tie is never split, so fewer may be rejected); needs near nodes only.
struct NewPlaceThreshold {
  double log_odds = 0.0;  // t; 0 without both kinds of node (FABMAP's own arg-max rule)
  size_t near = 0, far = 0;
  double near_accepted = 0.0, far_rejected = 0.0;  // at t, of the labelled nodes
  bool calibrated = false;
};
NewPlaceThreshold LearnNewPlaceThreshold(const std::vector<double>& log_odds,
                                         const std::vector<bool>& near, NewPlaceRule rule,
                                         double near_recall);

// The places of one data set divided into map and queries by `options.split`: interleaved by
// node or by session (InterleavedSplit with map_fraction), or the first session as the map.
// Sessions are told apart by id and ordered by their first node: every node of a session goes to
// the same side, however its nodes interleave in time with other sessions'.
struct SplitNodes {
  std::vector<EvaluationNode> map, queries;
};
SplitNodes SplitEvaluationNodes(const std::vector<EvaluationNode>& nodes,
                                const EvaluationOptions& options);

// Interleaved split: item i goes to the map when floor((i+1) f) > floor(i f), so that every
// stretch of 1/f items has one in the map. Returns true for map items.
std::vector<bool> InterleavedSplit(size_t count, double map_fraction);

// A localiser's answer to a query as a position: a map place's, or any position (k-NN averages
// its neighbours), or none (a rejection).
struct Estimate {
  bool located = false;
  double x_m = 0.0, y_m = 0.0;
  int floor = 0;
};

struct EvaluationMetrics {
  size_t queries = 0;
  std::vector<double> distances_m;       // the d of the rates below
  std::vector<double> correct_within;    // error <= d
  std::vector<double> misplaced_beyond;  // error > d (floor mistakes count as infinite)
  double rejection_rate = 0.0;
  double floor_mistake_rate = 0.0;
  std::vector<double> errors_m;  // per query; infinity: other floor; NaN: rejected
};

// The kPosterior answer (AnswerRule) from a query's posterior over the map's places:
// `place_probability[i]` is map node i's posterior (entries past the map and places at
// probability 0 take no part; ties: the lower index). No place with a positive posterior: not
// located. Building and floor votes break ties toward the most probable place's.
Estimate PosteriorEstimate(const std::vector<EvaluationNode>& map,
                           const std::vector<double>& place_probability, int places,
                           double temperature);

// `matches[i]` is the map index matched by query i, or -1 for a rejection.
EvaluationMetrics ComputeMetrics(const std::vector<EvaluationNode>& map,
                                 const std::vector<EvaluationNode>& queries,
                                 const std::vector<int64_t>& matches,
                                 const std::vector<double>& distances_m);

// For each d, the share of queries with a map place on their floor within d of them: what a
// localiser that answers with map places could reach at best (unmapped places lower it).
std::vector<double> NearestPlaceWithin(const std::vector<EvaluationNode>& map,
                                       const std::vector<EvaluationNode>& queries,
                                       const std::vector<double>& distances_m);

// The share of queries whose floor holds at least one map place: no localiser that answers with
// a map place's floor can classify more floors right (a split whose map skipped floors lowers it).
double ShareOnMappedFloors(const std::vector<EvaluationNode>& map,
                           const std::vector<EvaluationNode>& queries);
// The share of queries whose floor is `floors[i]` (none: no answer, never right); the floor
// classification of a localiser apart from where on the floor. Sizes must agree (else 0).
double FloorAccuracy(const std::vector<EvaluationNode>& queries,
                     const std::vector<std::optional<int>>& floors);

// Answers grouped by how far the query is from the map: `near` queries have a map place on their
// floor within `near_m` (a localiser should locate them), `far` ones none within `far_m` (places
// the map never saw: the right answer is a rejection). Queries in between are in neither.
struct MapDistanceGroup {
  size_t queries = 0;
  double rejection_rate = 0.0;      // of the group's queries
  double floor_mistake_rate = 0.0;  // answered with a place on another floor
  double located_rate = 0.0;        // answered on the right floor (any distance)
};
struct MapDistanceReport {
  double near_m = 0.0, far_m = 0.0;
  MapDistanceGroup near, far;
};
// `nearest_m[i]`: query i's distance to the nearest map place on its floor, infinity when there
// is none within at least `far_m` (NearestPlaceDistances with reach far_m).
MapDistanceReport ByMapDistance(const EvaluationMetrics& metrics,
                                const std::vector<double>& nearest_m, double near_m, double far_m);

// The same metrics from positions; `estimates[i]` answers query i (missing: a rejection).
EvaluationMetrics ComputeMetrics(const std::vector<EvaluationNode>& queries,
                                 const std::vector<Estimate>& estimates,
                                 const std::vector<double>& distances_m);

// One point of a precision-recall curve: a query is accepted when the posterior of its best
// mapped place reaches `threshold`; it is correct when that place is on the query's floor within
// d. Precision = correct / accepted; recall = correct / the queries that have a map place on their
// floor within d (those a localiser could get right). Precision is 1 where nothing is accepted.
struct PrecisionRecallPoint {
  double threshold = 0.0;
  size_t accepted = 0;
  std::vector<size_t> correct;  // per d
  std::vector<double> precision, recall;
};

// The curve over every distinct best-place posterior, from the highest (fewest accepted) down
// (all accepted); openFABMAP's most used output. `best_probability[i]` is query i's best mapped
// place's posterior (NaN: no place, never accepted), `best_error_m[i]` that place's distance
// (infinity on another floor), `nearest_m[i]` the distance of the nearest map place on the
// query's floor (infinity: none).
std::vector<PrecisionRecallPoint> PrecisionRecallCurve(const std::vector<double>& best_probability,
                                                       const std::vector<double>& best_error_m,
                                                       const std::vector<double>& nearest_m,
                                                       const std::vector<double>& distances_m);

// Per query, the distance to the nearest map place on its floor when it is at most `reach_m`
// (infinity otherwise, and when the floor has no place).
std::vector<double> NearestPlaceDistances(const std::vector<EvaluationNode>& map,
                                          const std::vector<EvaluationNode>& queries,
                                          double reach_m);

}  // namespace ratslam::fabmap

#endif  // RATSLAM_FUSION_FABMAP_EVALUATION_H_
