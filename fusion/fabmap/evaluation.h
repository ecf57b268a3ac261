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
#include "common/status.h"
#include "sensors/dataset/dataset.h"

namespace ratslam::fabmap {

// A place of the benchmark: where it is and what was sensed there.
struct EvaluationNode {
  double x_m = 0.0, y_m = 0.0;
  int floor = 0;
  double time_s = 0.0;
  double travelled_m = 0.0;  // along its session (Wi-Fi tree spacing); NaN: not recorded
  int session = 0;
  std::string image;                             // image path, if any
  std::optional<std::vector<WifiReading>> wifi;  // scan, if any
};

// kFirstSession: the first session makes the map, every other one queries it.
enum class SplitUnit { kNode, kSession, kFirstSession };
std::string ToString(SplitUnit unit);
StatusOr<SplitUnit> SplitUnitFromString(const std::string& name);

struct EvaluationOptions {
  SplitUnit split =
      SplitUnit::kNode;          // when map and query are one data set: split by node or session
  double map_fraction = 0.4;     // share of nodes (or sessions) that make the map (paper: 40%)
  double frame_spacing_m = 0.5;  // image folders without positions: metres per frame
  double image_wifi_max_gap_s = 10.0;  // an image takes a scan at most this far in time

  bool IsValid(std::string* error) const;
  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("split", split,
      "one data set for map and queries: split by node, session, or first_session (map = the "
      "first session, queries = the others)",
      schema::Any());
    v("map_fraction", map_fraction, "share of nodes (or sessions) in the map; the rest query",
      schema::Unit("").Above(0).Below(1));
    v("frame_spacing_m", frame_spacing_m,
      "image folders have no positions: frame i is at i * this along its floor",
      schema::Unit("m").Positive());
    v("image_wifi_max_gap_s", image_wifi_max_gap_s,
      "an image is paired with a Wi-Fi scan at most this far in time",
      schema::Unit("s").NonNegative());
  }
};

// The places of one data set divided into map and queries by `options.split`: interleaved by
// node or by session (InterleavedSplit with map_fraction), or the first session as the map.
struct SplitNodes {
  std::vector<EvaluationNode> map, queries;
};
SplitNodes SplitEvaluationNodes(const std::vector<EvaluationNode>& nodes,
                                const EvaluationOptions& options);

// Interleaved split: item i goes to the map when floor((i+1) f) > floor(i f), so that every
// stretch of 1/f items has one in the map. Returns true for map items.
std::vector<bool> InterleavedSplit(size_t count, double map_fraction);

struct EvaluationMetrics {
  size_t queries = 0;
  std::vector<double> distances_m;       // the d of the rates below
  std::vector<double> correct_within;    // error <= d
  std::vector<double> misplaced_beyond;  // error > d (floor mistakes count as infinite)
  double rejection_rate = 0.0;
  double floor_mistake_rate = 0.0;
  std::vector<double> errors_m;  // per query; infinity: other floor; NaN: rejected
};

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

// A localiser's answer to a query as a position: a map place's, or any position (k-NN averages
// its neighbours), or none (a rejection).
struct Estimate {
  bool located = false;
  double x_m = 0.0, y_m = 0.0;
  int floor = 0;
};
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
