#include "fusion/fabmap/localiser.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace ratslam::fabmap {

namespace {
constexpr std::pair<FabmapMode, const char*> kModeNames[] = {
    {FabmapMode::kVision, "vision"},
    {FabmapMode::kWifi, "wifi"},
    {FabmapMode::kEarly, "early"},
    {FabmapMode::kLate, "late"},
    {FabmapMode::kWifiGuided, "wifi_guided"},
    {FabmapMode::kWifiCheck, "wifi_check"}};
}  // namespace

std::string ToString(FabmapMode mode) {
  for (const auto& [m, name] : kModeNames) {
    if (m == mode) return name;
  }
  return "?";
}

StatusOr<FabmapMode> FabmapModeFromString(const std::string& name) {
  std::string valid;
  for (const auto& [m, n] : kModeNames) {
    if (name == n) return m;
    valid += (valid.empty() ? "" : ", ") + std::string(n);
  }
  return Status::Error("unknown FABMAP mode '" + name + "' (expected one of " + valid + ")");
}

bool UsesVision(FabmapMode mode) { return mode != FabmapMode::kWifi; }
bool UsesWifi(FabmapMode mode) { return mode != FabmapMode::kVision; }

bool LocaliserOptions::IsValid(std::string* error) const {
  return schema::CheckFields(*this, error);
}

Observation Localiser::WifiWords(const Query& query) const {
  return query.wifi ? wifi_vocabulary_.Encode(*query.wifi) : Observation{};
}

StatusOr<std::unique_ptr<Localiser>> Localiser::Create(const LocaliserSettings& settings,
                                                       const VisualModel* visual,
                                                       const WifiExploration& exploration) {
  std::string error;
  const auto check = [&](bool ok, const char* what) {
    return ok ? Status::Ok() : Status::Error(std::string(what) + ": " + error);
  };
  RATSLAM_RETURN_IF_ERROR(check(settings.localiser.IsValid(&error), "[fabmap]"));
  RATSLAM_RETURN_IF_ERROR(check(settings.fabmap.IsValid(&error), "[fabmap_model]"));
  RATSLAM_RETURN_IF_ERROR(check(settings.wifi_words.IsValid(&error), "[wifi_words]"));
  RATSLAM_RETURN_IF_ERROR(check(settings.virtual_wifi.IsValid(&error), "[virtual_wifi]"));
  const FabmapMode mode = settings.localiser.mode;
  if (UsesVision(mode) && (visual == nullptr || visual->tree.size() == 0)) {
    return Status::Error("FABMAP mode " + ToString(mode) + " needs a visual vocabulary");
  }
  std::unique_ptr<Localiser> l(new Localiser(settings));
  if (UsesVision(mode)) l->visual_words_ = visual->tree.size();
  if (UsesVision(mode) && mode != FabmapMode::kEarly) {
    const DetectorBlock block{0, l->visual_words_, settings.visual_detector};
    auto model = FabmapModel::Create(visual->tree, {block}, visual->samples, settings.fabmap);
    if (!model.ok()) return model.status().WithContext("visual FABMAP");
    l->vision_ = *std::move(model);
  }
  if (!UsesWifi(mode)) return l;

  // Wi-Fi vocabulary, tree and virtual unknown world from the exploration scans.
  for (const auto& scan : exploration.scans) l->wifi_vocabulary_.AddAccessPoints(scan);
  if (l->wifi_vocabulary_.size() == 0) {
    return Status::Error("FABMAP mode " + ToString(mode) +
                         " needs Wi-Fi scans to explore, and there is no usable access point");
  }
  std::vector<Observation> tree_observations;
  for (size_t k : SpacedIndices(exploration.travelled_m, exploration.time_s,
                                settings.localiser.wifi_tree_min_distance_m,
                                settings.localiser.wifi_tree_min_interval_s)) {
    tree_observations.push_back(l->wifi_vocabulary_.Encode(exploration.scans[k]));
  }
  l->wifi_exploration_scans_ = exploration.scans.size();
  l->wifi_tree_scans_ = tree_observations.size();
  auto wifi_tree =
      LearnChowLiuTree(tree_observations, l->wifi_vocabulary_.size(), settings.chow_liu);
  if (!wifi_tree.ok()) return wifi_tree.status().WithContext("Wi-Fi Chow-Liu tree");
  double mean_aps = 0.0, sigma_aps = 0.0;
  CountStatistics(exploration.scans, &mean_aps, &sigma_aps);
  std::vector<Observation> virtual_samples;
  if (settings.virtual_wifi.use_exploration_scans) {
    for (const auto& scan : exploration.scans) {
      virtual_samples.push_back(l->wifi_vocabulary_.Encode(scan));
    }
  } else {
    virtual_samples =
        VirtualWifiSamples(l->wifi_vocabulary_, mean_aps, sigma_aps, settings.virtual_wifi);
  }

  const uint32_t wifi_size = l->wifi_vocabulary_.size();
  if (mode != FabmapMode::kEarly) {
    const DetectorBlock block{0, wifi_size, settings.wifi_detector};
    auto model = FabmapModel::Create(*wifi_tree, {block}, virtual_samples, settings.fabmap);
    if (!model.ok()) return model.status().WithContext("Wi-Fi FABMAP");
    l->wifi_ = *std::move(model);
    return l;
  }
  // Early fusion: visual words first, Wi-Fi words after them; sample i of the joint unknown
  // world is visual sample i and Wi-Fi sample i (the shorter list repeats).
  std::vector<Observation> joint_samples;
  const size_t n = std::max(visual->samples.size(), virtual_samples.size());
  for (size_t i = 0; i < n; ++i) {
    Observation vs = visual->samples[i % visual->samples.size()];
    std::sort(vs.begin(), vs.end());
    vs.erase(std::unique(vs.begin(), vs.end()), vs.end());
    joint_samples.push_back(l->Joined(vs, virtual_samples[i % virtual_samples.size()]));
  }
  const DetectorBlock blocks[2] = {{0, l->visual_words_, settings.visual_detector},
                                   {l->visual_words_, wifi_size, settings.wifi_detector}};
  auto model = FabmapModel::Create(JoinForest(visual->tree, *wifi_tree), {blocks[0], blocks[1]},
                                   std::move(joint_samples), settings.fabmap);
  if (!model.ok()) return model.status().WithContext("early-fusion FABMAP");
  l->early_ = *std::move(model);
  return l;
}

Observation Localiser::Joined(const Observation& visual_words,
                              const Observation& wifi_words) const {
  Observation joined = visual_words;
  for (WordId w : wifi_words) joined.push_back(w + visual_words_);
  return joined;
}

Observation Localiser::VisualWords(const Query& query) const {
  Observation visual = query.visual;
  std::sort(visual.begin(), visual.end());
  visual.erase(std::unique(visual.begin(), visual.end()), visual.end());
  while (!visual.empty() && visual.back() >= visual_words_) visual.pop_back();
  return visual;
}

Status Localiser::AddPlace(const Query& place) {
  const Observation visual = vision_ || early_ ? VisualWords(place) : Observation{};
  if (vision_) RATSLAM_RETURN_IF_ERROR(vision_->AddPlace(visual).status());
  if (wifi_) RATSLAM_RETURN_IF_ERROR(wifi_->AddPlace(WifiWords(place)).status());
  if (early_) RATSLAM_RETURN_IF_ERROR(early_->AddPlace(Joined(visual, WifiWords(place))).status());
  ++places_;
  return Status::Ok();
}

StatusOr<std::unique_ptr<Localiser>> Localiser::Build(const LocaliserSettings& settings,
                                                      const VisualModel* visual,
                                                      const std::vector<MapNode>& map) {
  WifiExploration exploration;
  for (const MapNode& node : map) {
    if (!node.wifi) continue;
    exploration.scans.push_back(*node.wifi);
    exploration.travelled_m.push_back(node.travelled_m);
    exploration.time_s.push_back(node.time_s);
  }
  auto l = Create(settings, visual, exploration);
  if (!l.ok()) return l.status();
  for (size_t i = 0; i < map.size(); ++i) {
    if (UsesVision(settings.localiser.mode) && !map[i].visual.empty()) {
      const WordId top = *std::max_element(map[i].visual.begin(), map[i].visual.end());
      if (top >= (*l)->visual_words_) {
        return Status::Error("map node " + std::to_string(i) + ": word " + std::to_string(top) +
                             " is outside the vocabulary");
      }
    }
    RATSLAM_RETURN_IF_ERROR((*l)->AddPlace({map[i].visual, map[i].wifi}));
  }
  return l;
}

std::vector<uint32_t> Localiser::WifiCandidates(const Observation& wifi_words) const {
  std::vector<double> log_likelihood;
  wifi_->LogLikelihoods(wifi_words, &log_likelihood);
  std::vector<uint32_t> order(log_likelihood.size());
  std::iota(order.begin(), order.end(), 0u);
  const size_t keep =
      std::min(order.size(), static_cast<size_t>(settings_.localiser.max_candidates));
  std::partial_sort(order.begin(), order.begin() + keep, order.end(), [&](uint32_t a, uint32_t b) {
    return log_likelihood[a] > log_likelihood[b] ||
           (log_likelihood[a] == log_likelihood[b] && a < b);
  });
  order.resize(keep);
  if (!order.empty()) {
    const double floor = log_likelihood[order.front()] - settings_.localiser.candidate_log_margin;
    while (!order.empty() && log_likelihood[order.back()] < floor) order.pop_back();
  }
  return order;
}

LocalisationResult Localiser::Localise(const Query& query) const {
  const Observation visual = vision_ || early_ ? VisualWords(query) : Observation{};
  switch (settings_.localiser.mode) {
    case FabmapMode::kVision:
      return vision_->Localise(visual);
    case FabmapMode::kWifi:
      return wifi_->Localise(WifiWords(query));
    case FabmapMode::kEarly:
      return early_->Localise(Joined(visual, WifiWords(query)));
    case FabmapMode::kLate: {
      // eq. 4 over the n_M places and the new place; p(L_i) is uniform, so it cancels in alpha.
      const LocalisationResult a = vision_->Localise(visual);
      const LocalisationResult b = wifi_->Localise(WifiWords(query));
      LocalisationResult fused;
      fused.place_probability.resize(places_);
      double total = a.new_place_probability * b.new_place_probability;
      for (uint32_t i = 0; i < places_; ++i) {
        fused.place_probability[i] = a.place_probability[i] * b.place_probability[i];
        total += fused.place_probability[i];
      }
      if (!(total > 0.0)) {  // both posteriors underflowed everywhere they overlap
        fused.new_place_probability = 1.0;
        fused.best_probability = 1.0;
        return fused;
      }
      fused.new_place_probability = a.new_place_probability * b.new_place_probability / total;
      fused.best_probability = fused.new_place_probability;
      for (uint32_t i = 0; i < places_; ++i) {
        fused.place_probability[i] /= total;
        if (fused.best_mapped_place < 0 ||
            fused.place_probability[i] > fused.best_mapped_probability) {
          fused.best_mapped_place = i;
          fused.best_mapped_probability = fused.place_probability[i];
        }
        if (fused.place_probability[i] > fused.best_probability) {
          fused.best_probability = fused.place_probability[i];
          fused.best_place = i;
        }
      }
      // Each sensor's odds of the best place against the new place multiply (eq. 4); from the
      // posteriors, so saturated ones give +-inf.
      if (fused.best_mapped_place >= 0) {
        fused.best_mapped_log_odds =
            std::log(fused.best_mapped_probability) - std::log(fused.new_place_probability);
      }
      return fused;
    }
    case FabmapMode::kWifiGuided:
      return vision_->LocaliseAmong(visual, WifiCandidates(WifiWords(query)));
    case FabmapMode::kWifiCheck: {
      LocalisationResult r = vision_->Localise(visual);
      // The best mapped place is the visual match whenever there is one (both are the arg-max).
      if (r.best_mapped_place >= 0) {
        const std::vector<uint32_t> candidates = WifiCandidates(WifiWords(query));
        if (std::find(candidates.begin(), candidates.end(), r.best_mapped_place) ==
            candidates.end()) {
          if (r.best_place >= 0) {
            r.best_place = -1;  // Wi-Fi does not confirm the visual match: rejected
            r.best_probability = r.new_place_probability;
          }
          r.best_mapped_place = -1;  // and at any threshold
          r.best_mapped_probability = 0.0;
          r.best_mapped_log_odds = -std::numeric_limits<double>::infinity();
        }
      }
      return r;
    }
  }
  return {};
}

}  // namespace ratslam::fabmap
