// Options of the FABMAP front end ([front_end] kind = "fabmap") and what it is built from.
//
// kFabmap: FABMAP (fusion/fabmap) decides: a place it recognises with at least
// match_probability is the active view; otherwise (the new place wins) the observation becomes a
// new place and template. With decide_by_log_odds the best mapped place is the active view when
// its log odds against the new place reach match_log_odds (the log of the two posteriors' ratio,
// from the likelihoods, so finite where the posteriors saturate at 0 and 1): the rule whose
// threshold `ratslam evaluate` learns ([evaluation] calibrate_new_place). Any FABMAP mode works
// (vision, wifi, early, late, sequential). The Wi-Fi words, tree and virtual samples come from an
// exploration of the data set's own scans (the fusion paper's section 3: Wi-Fi vocabularies exist
// only after exploring), spaced by odometry travel and time; the visual model is loaded from
// [visual_model] file or trained.
#ifndef RATSLAM_FUSION_FABMAP_FRONT_END_OPTIONS_H_
#define RATSLAM_FUSION_FABMAP_FRONT_END_OPTIONS_H_

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "common/schema.h"
#include "common/status.h"
#include "fusion/fabmap/localiser.h"
#include "fusion/fabmap/visual_model.h"
#include "fusion/fabmap/vocabulary.h"

namespace ratslam::fusion {

// Where the FABMAP front end's Wi-Fi words, tree and unknown world come from.
//   kWholeDataSet: every scan of the data set, future sessions included (an exploration done
//     before the run, as in the fusion paper's benchmark; not causal).
//   kOnline: only the scans seen so far: learnt after `online_first_scans` scans and again each
//     time the count doubles (mapped places are re-added to the relearnt model); before the first
//     model every frame is a new place. A decision at time t never depends on data after t.
enum class WifiLearning { kWholeDataSet, kOnline };
std::string ToString(WifiLearning learning);
StatusOr<WifiLearning> WifiLearningFromString(const std::string& name);

struct FabmapFrontEndOptions {
  double match_probability = 0.5;  // least posterior of the best place to re-use its template
  int recency_templates = 0;       // a match this many templates old or newer: no injection
  double recency_s = 10.0;         // nor one made less than this long ago
  double max_wifi_age_s = 5.0;     // an older newest scan counts as absent at an image frame
  WifiLearning wifi_learning = WifiLearning::kWholeDataSet;  // see WifiLearning
  int online_first_scans = 20;      // kOnline: scans before the first Wi-Fi model
  bool decide_by_log_odds = false;  // the best place's log odds, not its posterior, decide
  double match_log_odds = 0.0;      // with decide_by_log_odds: least log odds of the best place
  // With decide_by_log_odds: places of earlier sessions are judged by their own threshold. A
  // revisit within one walk and a revisit of another walk's place differ in how well their scans
  // agree (another day, phone or pose), so one threshold cannot serve both (docs/results/ipin.md,
  // "The FABMAP front end's new-place threshold"). The best place of the current session must
  // reach match_log_odds, the best of the earlier sessions earlier_session_log_odds; when both
  // do, the more probable one wins. Per-place posteriors only: the sequential modes keep one rule.
  bool earlier_sessions_apart = false;
  double earlier_session_log_odds = 0.0;
  // Learn earlier_session_log_odds from revisits verified outside the front end ([wifi_sequence]:
  // each inlier of an accepted sequence loop pairs a scan of this session with one of an earlier
  // session): the log odds of each such scan for the place its partner scan became or matched;
  // once learn_min_revisits are known the threshold is the highest that learn_near_recall of
  // them pass (as `evaluate`'s near-recall rule). Until then the configured value holds.
  bool learn_earlier_session_log_odds = false;
  double learn_near_recall = 0.9;
  int learn_min_revisits = 10;
  // Learn it in a first pass instead, and map in a second: `replay` runs the data twice, first
  // with the Wi-Fi sequence loop closer and the learner starting from match_log_odds (no
  // hand-set value), then under this configuration with the learnt threshold from the first
  // frame on (earlier_session_log_odds when the first pass verified fewer than
  // learn_min_revisits). Learning inside one pass comes too late: by the time the loop closer
  // has verified enough revisits, much of the later walk has made places of its own
  // (docs/results/ipin.md). A resumed or localised map keeps the threshold it was saved with.
  bool calibrate_earlier_session_log_odds = false;
  // Per-device RSSI offset, estimated online as in [fused] (sensors/rssi_offset.h) and removed
  // from a later session's scans before they become Wi-Fi words and places.
  bool online_rssi_offset = false;
  int rssi_offset_min_common_aps = 5;
  int rssi_offset_min_estimates = 10;

  bool IsValid(std::string* error) const;
  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("match_probability", match_probability,
      "least FABMAP posterior of the best place for its template to become active",
      schema::Unit("").Above(0).AtMost(1));
    v("recency_templates", recency_templates,
      "matches to one of the newest this-many templates re-use it without injection",
      schema::Unit("templates").NonNegative());
    v("recency_s", recency_s, "so do matches to a template made less than this long ago",
      schema::Unit("s").NonNegative());
    v("max_wifi_age_s", max_wifi_age_s, "a Wi-Fi scan older than this counts as absent at a frame",
      schema::Unit("s").NonNegative());
    v("wifi_learning", wifi_learning,
      "Wi-Fi words, tree and unknown world from whole_data_set (every scan, future included) or "
      "online (only the scans seen so far, relearnt as their number doubles)",
      schema::Any());
    v("online_first_scans", online_first_scans,
      "online: scans before the first Wi-Fi model (every frame is a new place until then)",
      schema::Unit("scans").AtLeast(1));
    v("decide_by_log_odds", decide_by_log_odds,
      "the best mapped place becomes active when its log odds against the new place reach "
      "match_log_odds (instead of its posterior reaching match_probability)",
      schema::Any());
    v("match_log_odds", match_log_odds,
      "decide_by_log_odds: least log(p(best place) / p(new place)), nats; 0 is the arg-max, "
      "negative values accept places the new place beats",
      schema::Unit("nats").Within(-1000, 1000));
    v("earlier_sessions_apart", earlier_sessions_apart,
      "decide_by_log_odds: places of earlier sessions need earlier_session_log_odds, those of the "
      "current session match_log_odds; the more probable of two that pass wins",
      schema::Any());
    v("earlier_session_log_odds", earlier_session_log_odds,
      "earlier_sessions_apart: least log odds of the best place of an earlier session, nats",
      schema::Unit("nats").Within(-1000, 1000));
    v("learn_earlier_session_log_odds", learn_earlier_session_log_odds,
      "earlier_sessions_apart: learn earlier_session_log_odds from the Wi-Fi sequence loop "
      "closer's verified revisits ([wifi_sequence] enabled); the configured value holds until "
      "learn_min_revisits are known",
      schema::Any());
    v("calibrate_earlier_session_log_odds", calibrate_earlier_session_log_odds,
      "earlier_sessions_apart: replay twice, learning earlier_session_log_odds in the first pass "
      "(loop closer and learner on, from match_log_odds) and mapping with it in the second",
      schema::Any());
    v("learn_near_recall", learn_near_recall,
      "learn_earlier_session_log_odds: share of the verified revisits the learnt threshold "
      "accepts",
      schema::Unit("").Above(0).AtMost(1));
    v("learn_min_revisits", learn_min_revisits,
      "learn_earlier_session_log_odds: verified revisits before the learnt threshold replaces "
      "the configured one",
      schema::Unit("revisits").AtLeast(1));
    v("online_rssi_offset", online_rssi_offset,
      "estimate each later session's RSSI offset to the earlier sessions' places online and "
      "remove it from its scans before they become Wi-Fi words (phones that read several dB "
      "apart)",
      schema::Any());
    v("rssi_offset_min_common_aps", rssi_offset_min_common_aps,
      "APs a scan must share with an earlier session's place to estimate the offset",
      schema::Unit("APs").AtLeast(1));
    v("rssi_offset_min_estimates", rssi_offset_min_estimates,
      "offset estimates of a session before its median is applied",
      schema::Unit("scans").AtLeast(1));
  }
};

// FABMAP localisation (fusion/fabmap): modes, models, words and the benchmark's split.
struct FabmapSettings {
  fabmap::LocaliserSettings localiser;
  fabmap::FeatureOptions features;
  fabmap::VocabularyOptions vocabulary;
  fabmap::VisualModelOptions visual_model;
  FabmapFrontEndOptions front_end;

  bool IsValid(std::string* error) const;

 private:
  bool LearningFits(std::string* error) const;
};

// What the FABMAP front end is built from, prepared once per run (PrepareFabmapResources).
struct FabmapResources {
  std::optional<fabmap::TrainedVisualModel> visual;  // to turn images into words
  // The localiser with no places yet (words, trees, unknown world): each front end, and each
  // restore, starts from a copy instead of learning the Wi-Fi tree again. Whole-data-set
  // learning only; online learning builds its own from `scans`.
  std::shared_ptr<const fabmap::Localiser> empty_localiser;
  // Every scan of the data set in order, with the odometry travel before it (online learning
  // uses the first n of them after the n-th scan, never more).
  fabmap::WifiExploration scans;
};

// How a FABMAP front end learnt its Wi-Fi model, for the run's summary.
struct FabmapLearningReport {
  WifiLearning wifi_learning = WifiLearning::kWholeDataSet;
  uint64_t wifi_learned_from_scans = 0;  // scans behind the current Wi-Fi model
  uint64_t wifi_relearnt = 0;            // times the model was (re)built during the run
  uint64_t wifi_tree_scans = 0;          // of the scans, those that learnt the Wi-Fi tree
  // earlier_sessions_apart: the earlier sessions' threshold in use (nats), and with
  // learn_earlier_session_log_odds the verified revisits it was learnt from (0: configured).
  std::optional<double> earlier_session_log_odds;
  std::optional<uint64_t> verified_revisits;
  // calibrate_earlier_session_log_odds: whether the threshold came from the first pass (false:
  // too few verified revisits there, the configured value held); verified_revisits are then
  // the first pass's.
  std::optional<bool> calibrated;
};

}  // namespace ratslam::fusion

#endif  // RATSLAM_FUSION_FABMAP_FRONT_END_OPTIONS_H_
