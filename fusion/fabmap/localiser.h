// Global localisation with FABMAP over vision, Wi-Fi, or both (the fusion paper's section 4).
//
// The map is a list of nodes, each a visual observation and/or a Wi-Fi scan. Wi-Fi words are
// learnt from the map's scans (section 3.1), the Wi-Fi Chow-Liu tree from map scans that are far
// enough apart (section 3.2), the Wi-Fi unknown world from virtual samples (section 3.3). The
// visual vocabulary, tree and unknown-world samples come from offline training (section 2).
// Modes:
//   vision, wifi   one modality alone;
//   early          one FABMAP over concatenated visual and Wi-Fi words, the two trees used as one
//                  forest and the unknown-world samples concatenated (sections 4.2-4.3);
//   late           eq. 4: p(L_i) proportional to p_vision(L_i) p_wifi(L_i) / p(L_i), with
//                  p(L_i) = 1 / (n_M + 1) for the n_M places and the new place;
//   wifi_guided    visual FABMAP over the Wi-Fi candidates only (section 4.1);
//   wifi_check     the visual result stands only if Wi-Fi lists it as a candidate, else it is a
//                  rejection (section 4.1).
// Sequential fusion needs several Wi-Fi candidates, not FABMAP's single arg-max (the paper uses
// Stumm et al. 2013). Our normalisation: the candidates are the places whose Wi-Fi likelihood is
// within `candidate_log_margin` nats of the best one, at most `max_candidates` of them, best
// first; i.e. places with likelihood ratio to the best of at least exp(-margin).
#ifndef RATSLAM_FUSION_FABMAP_LOCALISER_H_
#define RATSLAM_FUSION_FABMAP_LOCALISER_H_

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/schema.h"
#include "common/sensor_samples.h"
#include "common/status.h"
#include "fusion/fabmap/chow_liu.h"
#include "fusion/fabmap/fabmap.h"
#include "fusion/fabmap/wifi_words.h"

namespace ratslam::fabmap {

enum class FabmapMode { kVision, kWifi, kEarly, kLate, kWifiGuided, kWifiCheck };
std::string ToString(FabmapMode mode);
StatusOr<FabmapMode> FabmapModeFromString(const std::string& name);
bool UsesVision(FabmapMode mode);
bool UsesWifi(FabmapMode mode);

struct LocaliserOptions {
  FabmapMode mode = FabmapMode::kWifi;    // which sensors, and how they are fused
  int max_candidates = 20;                // Wi-Fi candidates for sequential fusion
  double candidate_log_margin = 20.0;     // nats below the best Wi-Fi likelihood still a candidate
  double wifi_tree_min_distance_m = 1.0;  // spacing of the scans that learn the Wi-Fi tree
  double wifi_tree_min_interval_s = 0.0;  // (section 3.2): travel and time since the last one

  bool IsValid(std::string* error) const;
  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("mode", mode, "vision, wifi, early, late, wifi_guided or wifi_check (paper section 4)",
      schema::Any());
    v("max_candidates", max_candidates, "Wi-Fi candidates at most, for sequential fusion",
      schema::Unit("places").AtLeast(1));
    v("candidate_log_margin", candidate_log_margin,
      "a place within this many nats of the best Wi-Fi likelihood is a candidate",
      schema::Unit("nats").NonNegative());
    v("wifi_tree_min_distance_m", wifi_tree_min_distance_m,
      "Wi-Fi tree: a scan is used only this far (travel) from the previously used one",
      schema::Unit("m").NonNegative());
    v("wifi_tree_min_interval_s", wifi_tree_min_interval_s,
      "Wi-Fi tree: and only this long after it", schema::Unit("s").NonNegative());
  }
};

// Everything the localiser is configured with.
struct LocaliserSettings {
  LocaliserOptions localiser;
  FabmapOptions fabmap;
  DetectorModel visual_detector;  // openFABMAP's defaults (0.39, 0)
  // An access point in range is heard far more reliably than a visual word is detected: with
  // 0.39 nearly every UJIIndoorLoc query is rejected (97%); 0.9 gives 6.7% (see
  // docs/results/fabmap.md).
  DetectorModel wifi_detector{0.9, 0.0};
  WifiWordOptions wifi_words;
  VirtualSampleOptions virtual_wifi;
  ChowLiuOptions chow_liu;
};

// The offline visual model: its Chow-Liu tree and unknown-world sample observations.
struct VisualModel {
  ChowLiuTree tree;
  std::vector<Observation> samples;
};

struct MapNode {
  Observation visual;                            // visual words (vision modes)
  std::optional<std::vector<WifiReading>> wifi;  // the node's scan, if any
  double travelled_m = 0.0;  // along the exploration, for tree spacing (NaN: not recorded)
  double time_s = 0.0;
};

struct Query {
  Observation visual;
  std::optional<std::vector<WifiReading>> wifi;
};

// Scans of an exploration: they define the Wi-Fi words, tree (spaced by travel and time) and
// virtual unknown world. A NaN travel means the data set has none: spacing is by time only.
struct WifiExploration {
  std::vector<std::vector<WifiReading>> scans;
  std::vector<double> travelled_m;
  std::vector<double> time_s;
};

class Localiser {
 public:
  // An empty map; `visual` is needed by the modes that use vision, `exploration` by those that
  // use Wi-Fi.
  static StatusOr<std::unique_ptr<Localiser>> Create(const LocaliserSettings& settings,
                                                     const VisualModel* visual,
                                                     const WifiExploration& exploration);
  // Create with the map's own scans as exploration, then AddPlace for every node.
  static StatusOr<std::unique_ptr<Localiser>> Build(const LocaliserSettings& settings,
                                                    const VisualModel* visual,
                                                    const std::vector<MapNode>& map);
  // Appends a place (the next index).
  Status AddPlace(const Query& place);
  uint32_t places() const { return places_; }
  uint32_t wifi_words() const { return wifi_vocabulary_.size(); }
  // Scans of the exploration, and how many of them (after spacing) learnt the Wi-Fi tree.
  size_t wifi_exploration_scans() const { return wifi_exploration_scans_; }
  size_t wifi_tree_scans() const { return wifi_tree_scans_; }
  // best_place indexes the map nodes; -1 is the new place (a rejection).
  LocalisationResult Localise(const Query& query) const;
  // Wi-Fi candidates for sequential fusion, best first.
  std::vector<uint32_t> WifiCandidates(const Observation& wifi_words) const;

 private:
  explicit Localiser(const LocaliserSettings& settings)
      : settings_(settings), wifi_vocabulary_(settings.wifi_words) {}
  Observation WifiWords(const Query& query) const;
  Observation VisualWords(const Query& query) const;  // sorted, in the vocabulary
  Observation Joined(const Observation& visual_words, const Observation& wifi_words) const;

  LocaliserSettings settings_;
  uint32_t places_ = 0;
  uint32_t visual_words_ = 0;
  size_t wifi_exploration_scans_ = 0;
  size_t wifi_tree_scans_ = 0;
  WifiVocabulary wifi_vocabulary_;
  std::optional<FabmapModel> vision_, wifi_, early_;
};

}  // namespace ratslam::fabmap

#endif  // RATSLAM_FUSION_FABMAP_LOCALISER_H_
