#include "session/evaluation_session.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "common/number_text.h"
#include "io/config.h"
#include "io/provenance_json.h"
#include "io/visual_model_file.h"
#include "session/evaluation_baselines.h"
#include "session/evaluation_nodes.h"

namespace ratslam::session {
namespace {

std::string Key(double d) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", d);
  return text;
}

const std::vector<double> kDistancesM = {2, 5, 10, 20};

// An object keyed by the distances of kDistancesM ("2", "5", ...).
nlohmann::ordered_json ByDistance(const std::vector<double>& values) {
  nlohmann::ordered_json o = nlohmann::ordered_json::object();
  for (size_t k = 0; k < kDistancesM.size() && k < values.size(); ++k) {
    o[Key(kDistancesM[k])] = values[k];
  }
  return o;
}

// The rates of one method: correct within d, misplaced beyond d, rejections, floor mistakes, and
// those of queries near and far from the map (`nearest_m` as ByMapDistance takes it).
void AddRates(const fabmap::EvaluationMetrics& m, const std::vector<double>& nearest_m,
              const fabmap::EvaluationOptions& options, nlohmann::ordered_json* j) {
  (*j)["correct_within_m"] = ByDistance(m.correct_within);
  (*j)["misplaced_beyond_m"] = ByDistance(m.misplaced_beyond);
  (*j)["rejection_rate"] = m.rejection_rate;
  (*j)["floor_mistake_rate"] = m.floor_mistake_rate;
  const fabmap::MapDistanceReport r =
      fabmap::ByMapDistance(m, nearest_m, options.near_place_m, options.far_place_m);
  nlohmann::ordered_json& o = (*j)["by_map_distance"];
  o["near_m"] = r.near_m;
  o["far_m"] = r.far_m;
  for (const auto& [name, g] : {std::pair("near", &r.near), std::pair("far", &r.far)}) {
    o[name]["queries"] = g->queries;
    o[name]["rejection_rate"] = g->rejection_rate;
    o[name]["floor_mistake_rate"] = g->floor_mistake_rate;
    o[name]["located_rate"] = g->located_rate;
  }
}

}  // namespace

const std::vector<std::string>& EvaluationKeys() {
  static const std::vector<std::string> keys = {"mode",
                                                "map",
                                                "query",
                                                "config",
                                                "map_nodes",
                                                "queries",
                                                "correct_within_m",
                                                "misplaced_beyond_m",
                                                "rejection_rate",
                                                "floor_mistake_rate",
                                                "by_map_distance",
                                                "nearest_place_within_m",
                                                "average_precision_within_m",
                                                "new_place_calibration",
                                                "baselines",
                                                "floor_classification",
                                                "wifi_words",
                                                "wifi_map_scans",
                                                "wifi_tree_scans",
                                                "query_rssi_offsets_db",
                                                "visual_words",
                                                "query_time_ms",
                                                "wall_time_s",
                                                "run"};
  return keys;
}

EvaluationSession::EvaluationSession(EvaluationSessionOptions options, OutputFolder* out,
                                     const Clock* clock, ProgressSink* progress,
                                     ImageLoader* images)
    : options_(std::move(options)),
      out_(out),
      clock_(clock ? clock : &system_clock_),
      progress_(progress ? progress : &no_progress_),
      images_(images) {
  if (out_ == nullptr) throw std::invalid_argument("EvaluationSession needs an output folder");
  if (images_ == nullptr) {
    own_images_ = std::make_unique<dataset::FileImageLoader>();
    images_ = own_images_.get();
  }
  started_s_ = clock_->Seconds();
}

EvaluationSession::~EvaluationSession() = default;

fabmap::FabmapMode EvaluationSession::mode() const {
  return options_.pipeline.sensors.fabmap.localiser.localiser.mode;
}

Status EvaluationSession::Load() {
  std::string error;
  if (!options_.pipeline.IsValid(&error)) return Status::Error("configuration: " + error);
  RATSLAM_RETURN_IF_ERROR(out_->Write("config.toml", io::PrintConfig(options_.pipeline)));
  const bool vision = fabmap::UsesVision(mode());
  dataset::PhoneLogOptions phone;
  phone.lenient = options_.lenient;
  phone.pdr = options_.pipeline.pdr;
  const fabmap::EvaluationOptions& evaluation = options_.pipeline.evaluation;
  auto map_nodes = LoadEvaluationNodes(options_.map_path, true, vision, evaluation, phone,
                                       options_.pipeline.bag, options_.pipeline.video);
  if (!map_nodes.ok()) return map_nodes.status();
  std::error_code ec;
  if (std::filesystem::equivalent(options_.map_path, options_.query_path, ec)) {
    // One data set: the documented split by node, by session, or the first session as the map.
    fabmap::SplitNodes split = fabmap::SplitEvaluationNodes(*map_nodes, evaluation);
    result_.map = std::move(split.map);
    result_.queries = std::move(split.queries);
  } else {
    result_.map = *std::move(map_nodes);
    auto q = LoadEvaluationNodes(options_.query_path, false, vision, evaluation, phone,
                                 options_.pipeline.bag, options_.pipeline.video);
    if (!q.ok()) return q.status();
    result_.queries = *std::move(q);
  }
  if (result_.map.empty() || result_.queries.empty()) {
    return Status::Error("no map or no query nodes with ground truth (map " +
                         std::to_string(result_.map.size()) + ", queries " +
                         std::to_string(result_.queries.size()) + ")");
  }
  if (evaluation.online_rssi_offset) {
    result_.query_rssi_offsets =
        RemoveQueryRssiOffsets(result_.map, &result_.queries, evaluation.rssi_offset_min_common_aps,
                               evaluation.rssi_offset_min_estimates);
  }
  return Status::Ok();
}

Status EvaluationSession::Words(const std::vector<fabmap::EvaluationNode>& nodes,
                                const std::string& what, std::vector<fabmap::Observation>* words) {
  words->clear();
  for (size_t i = 0; i < nodes.size(); ++i) {
    if (stopped()) return Status::Error("evaluation stopped by request");
    if (nodes[i].image.empty()) {
      return Status::Error(what + " node " + std::to_string(i) + " has no image");
    }
    auto image = images_->Load(nodes[i].image);
    if (!image.ok()) return image.status();
    auto w = fabmap::ImageWords(*visual_, *image);
    if (!w.ok()) return w.status().WithContext(nodes[i].image);
    words->push_back(*std::move(w));
    progress_->Update({"visual words of " + what, i + 1, nodes.size()});
  }
  progress_->Finish();
  return Status::Ok();
}

Status EvaluationSession::Prepare() {
  const fusion::FabmapSettings& settings = options_.pipeline.sensors.fabmap;
  const bool vision = fabmap::UsesVision(mode());
  if (vision) {
    auto model = io::LoadOrTrainVisualModel(settings.visual_model, settings.features,
                                            settings.vocabulary, settings.localiser.chow_liu,
                                            *images_, [this](size_t done, size_t total) {
                                              progress_->Update({"training images", done, total});
                                            });
    if (!model.ok()) return model.status();
    progress_->Finish();
    visual_ = *std::move(model);
    trained_here_ = settings.visual_model.file.empty();
    if (trained_here_) {  // keep it for later runs
      RATSLAM_RETURN_IF_ERROR(out_->Write("visual_model.bin", fabmap::EncodeVisualModel(*visual_)));
    }
    RATSLAM_RETURN_IF_ERROR(Words(result_.map, "map", &map_words_));
    RATSLAM_RETURN_IF_ERROR(Words(result_.queries, "queries", &query_words_));
  }
  std::vector<size_t> all(result_.map.size());
  std::iota(all.begin(), all.end(), size_t{0});
  auto localiser = BuildLocaliser(all);
  if (!localiser.ok()) return localiser.status();
  localiser_ = *std::move(localiser);
  result_.wifi_words = localiser_->wifi_words();
  result_.wifi_map_scans = localiser_->wifi_exploration_scans();
  result_.wifi_tree_scans = localiser_->wifi_tree_scans();
  result_.visual_words = visual_ ? visual_->vocabulary.size() : 0u;
  result_.new_place = fabmap::NewPlaceThreshold();
  if (options_.pipeline.evaluation.calibrate_new_place) {
    RATSLAM_RETURN_IF_ERROR(CalibrateNewPlace());
  }
  return Status::Ok();
}

StatusOr<std::unique_ptr<fabmap::Localiser>> EvaluationSession::BuildLocaliser(
    const std::vector<size_t>& map_nodes) const {
  const bool vision = fabmap::UsesVision(mode());
  std::vector<fabmap::MapNode> places;
  for (size_t i : map_nodes) {
    fabmap::MapNode n;
    if (vision) n.visual = map_words_[i];
    n.wifi = result_.map[i].wifi;
    n.travelled_m = result_.map[i].travelled_m;
    n.time_s = result_.map[i].time_s;
    places.push_back(std::move(n));
  }
  return fabmap::Localiser::Build(options_.pipeline.sensors.fabmap.localiser,
                                  visual_ ? &visual_->model : nullptr, places);
}

Status EvaluationSession::CalibrateNewPlace() {
  const fabmap::EvaluationOptions& evaluation = options_.pipeline.evaluation;
  const bool vision = fabmap::UsesVision(mode());
  std::vector<int> sessions;
  for (const fabmap::EvaluationNode& n : result_.map) sessions.push_back(n.session);
  std::sort(sessions.begin(), sessions.end());
  sessions.erase(std::unique(sessions.begin(), sessions.end()), sessions.end());
  if (sessions.size() < 2) {
    return Status::Error(
        "[evaluation] calibrate_new_place needs at least two map sessions; the "
        "map has " +
        std::to_string(sessions.size()));
  }
  // Each fold of sessions in turn is held out: localised against a map of the others, its nodes
  // labelled near or far by their distance to that map.
  const size_t folds = std::min(sessions.size(), static_cast<size_t>(evaluation.calibration_folds));
  std::map<int, size_t> fold_of;
  for (size_t k = 0; k < sessions.size(); ++k) fold_of[sessions[k]] = k % folds;
  std::vector<double> log_odds;
  std::vector<bool> near;
  for (size_t k = 0; k < folds; ++k) {
    if (stopped()) return Status::Error("evaluation stopped by request");
    std::vector<size_t> rest, held;
    std::vector<fabmap::EvaluationNode> rest_nodes, held_nodes;
    for (size_t i = 0; i < result_.map.size(); ++i) {
      const bool out = fold_of[result_.map[i].session] == k;
      (out ? held : rest).push_back(i);
      (out ? held_nodes : rest_nodes).push_back(result_.map[i]);
    }
    auto localiser = BuildLocaliser(rest);
    if (!localiser.ok()) return localiser.status().WithContext("calibrating the new place");
    const std::vector<double> nearest = fabmap::NearestPlaceDistances(
        rest_nodes, held_nodes, std::numeric_limits<double>::infinity());
    for (size_t h = 0; h < held.size(); ++h) {
      const bool is_near = nearest[h] <= evaluation.near_place_m;
      if (!is_near && !(nearest[h] > evaluation.far_place_m)) continue;
      fabmap::Query q;
      if (vision) q.visual = map_words_[held[h]];
      q.wifi = result_.map[held[h]].wifi;
      log_odds.push_back((*localiser)->Localise(q).best_mapped_log_odds);
      near.push_back(is_near);
    }
    progress_->Update({"calibrating the new place", k + 1, folds});
  }
  progress_->Finish();
  result_.new_place = fabmap::LearnNewPlaceThreshold(log_odds, near, evaluation.new_place_rule,
                                                     evaluation.new_place_near_recall);
  result_.new_place_sessions = sessions.size();
  result_.new_place_folds = folds;
  return Status::Ok();
}

Status EvaluationSession::Localise() {
  if (!localiser_) return Status::Error("evaluation session: Localise before Prepare");
  const bool vision = fabmap::UsesVision(mode());
  result_.matches.clear();
  result_.answers.clear();
  result_.match_probability.clear();
  result_.new_place_probability.clear();
  result_.best_mapped_place.clear();
  result_.best_mapped_probability.clear();
  result_.best_mapped_log_odds.clear();
  const double start = clock_->Seconds();
  for (size_t i = 0; i < result_.queries.size(); ++i) {
    if (stopped()) return Status::Error("evaluation stopped by request");
    fabmap::Query q;
    if (vision) q.visual = query_words_[i];
    q.wifi = result_.queries[i].wifi;
    fabmap::LocalisationResult r = localiser_->Localise(q);
    if (result_.new_place.calibrated) {
      // The learnt threshold decides between the best mapped place and the new place.
      const bool accept =
          r.best_mapped_place >= 0 && r.best_mapped_log_odds > result_.new_place.log_odds;
      r.best_place = accept ? r.best_mapped_place : -1;
      r.best_probability = accept ? r.best_mapped_probability : r.new_place_probability;
    }
    result_.matches.push_back(r.best_place);
    fabmap::Estimate answer;
    if (r.best_place >= 0) {
      const fabmap::EvaluationOptions& e = options_.pipeline.evaluation;
      if (e.answer == fabmap::AnswerRule::kPosterior) {
        answer = fabmap::PosteriorEstimate(result_.map, r.place_probability, e.answer_places,
                                           e.answer_temperature);
      } else {
        const fabmap::EvaluationNode& p = result_.map[static_cast<size_t>(r.best_place)];
        answer = {true, p.x_m, p.y_m, p.floor};
      }
    }
    result_.answers.push_back(answer);
    result_.match_probability.push_back(r.best_probability);
    result_.new_place_probability.push_back(r.new_place_probability);
    result_.best_mapped_place.push_back(r.best_mapped_place);
    result_.best_mapped_probability.push_back(r.best_mapped_probability);
    result_.best_mapped_log_odds.push_back(r.best_mapped_log_odds);
    progress_->Update({"queries", i + 1, result_.queries.size()});
  }
  progress_->Finish();
  result_.query_time_ms =
      1000.0 * (clock_->Seconds() - start) / static_cast<double>(result_.queries.size());
  result_.metrics = fabmap::ComputeMetrics(result_.queries, result_.answers, kDistancesM);
  {
    // The best mapped place's error (infinity on another floor) and posterior (NaN: no place).
    const fabmap::EvaluationMetrics best = fabmap::ComputeMetrics(
        result_.map, result_.queries, result_.best_mapped_place, kDistancesM);
    std::vector<double> probability = result_.best_mapped_probability;
    for (size_t i = 0; i < probability.size(); ++i) {
      if (result_.best_mapped_place[i] < 0) probability[i] = std::nan("");
    }
    result_.precision_recall = fabmap::PrecisionRecallCurve(
        probability, best.errors_m,
        fabmap::NearestPlaceDistances(result_.map, result_.queries, kDistancesM.back()),
        kDistancesM);
  }
  result_.baselines.clear();
  result_.floor_accuracy.clear();
  result_.queries_on_mapped_floors = fabmap::ShareOnMappedFloors(result_.map, result_.queries);
  {
    std::vector<std::optional<int>> floors(result_.queries.size());
    for (size_t i = 0; i < floors.size(); ++i) {
      if (result_.best_mapped_place[i] >= 0) {
        floors[i] = result_.map[static_cast<size_t>(result_.best_mapped_place[i])].floor;
      }
    }
    result_.floor_accuracy.emplace_back("fabmap_best_mapped_place",
                                        fabmap::FloorAccuracy(result_.queries, floors));
  }
  const bool map_has_wifi = std::any_of(result_.map.begin(), result_.map.end(),
                                        [](const fabmap::EvaluationNode& n) { return n.wifi; });
  if (map_has_wifi) {
    const std::vector<fabmap::Estimate> knn = KnnEstimates(result_.map, result_.queries);
    std::vector<std::optional<int>> floors(knn.size());
    for (size_t i = 0; i < knn.size(); ++i) {
      if (knn[i].located) floors[i] = knn[i].floor;
    }
    result_.floor_accuracy.emplace_back("knn", fabmap::FloorAccuracy(result_.queries, floors));
    result_.baselines.emplace_back("knn",
                                   fabmap::ComputeMetrics(result_.queries, knn, kDistancesM));
    const sensors::WifiMatcherOptions& wifi = options_.pipeline.sensors.wifi;
    result_.baselines.emplace_back(
        "fingerprint", fabmap::ComputeMetrics(
                           result_.queries,
                           FingerprintEstimates(result_.map, result_.queries, wifi), kDistancesM));
  }
  return Status::Ok();
}

Status EvaluationSession::WriteOutputs() {
  const fabmap::EvaluationMetrics& m = result_.metrics;
  nlohmann::ordered_json j;
  j["mode"] = fabmap::ToString(mode());
  j["map"] = options_.map_path;
  j["query"] = options_.query_path;
  j["config"] = options_.config_path;
  j["map_nodes"] = result_.map.size();
  j["queries"] = m.queries;
  const fabmap::EvaluationOptions& evaluation = options_.pipeline.evaluation;
  const std::vector<double> nearest = fabmap::NearestPlaceDistances(
      result_.map, result_.queries, std::numeric_limits<double>::infinity());
  AddRates(m, nearest, evaluation, &j);
  j["nearest_place_within_m"] =
      ByDistance(fabmap::NearestPlaceWithin(result_.map, result_.queries, kDistancesM));
  {
    // Average precision of the precision-recall curve (pr_curve.csv): sum of precision times
    // the recall gained at each point.
    std::vector<double> average(kDistancesM.size(), 0.0), last_recall(kDistancesM.size(), 0.0);
    for (const fabmap::PrecisionRecallPoint& p : result_.precision_recall) {
      for (size_t k = 0; k < kDistancesM.size(); ++k) {
        average[k] += p.precision[k] * (p.recall[k] - last_recall[k]);
        last_recall[k] = p.recall[k];
      }
    }
    j["average_precision_within_m"] = ByDistance(average);
  }
  if (evaluation.calibrate_new_place) {
    const fabmap::NewPlaceThreshold& t = result_.new_place;
    nlohmann::ordered_json& c = j["new_place_calibration"];
    c["sessions"] = result_.new_place_sessions;
    c["folds"] = result_.new_place_folds;
    c["near_nodes"] = t.near;
    c["far_nodes"] = t.far;
    c["rule"] = fabmap::ToString(evaluation.new_place_rule);
    if (evaluation.new_place_rule == fabmap::NewPlaceRule::kNearRecall) {
      c["near_recall"] = evaluation.new_place_near_recall;
    }
    c["calibrated"] = t.calibrated;
    c["log_odds_threshold"] = t.log_odds;
    c["near_accepted"] = t.near_accepted;
    c["far_rejected"] = t.far_rejected;
  }
  j["baselines"] = nlohmann::ordered_json::object();
  for (const auto& [name, b] : result_.baselines) {
    AddRates(b, nearest, evaluation, &j["baselines"][name]);
  }
  {
    nlohmann::ordered_json& f = j["floor_classification"];
    f["queries_on_mapped_floors"] = result_.queries_on_mapped_floors;
    for (const auto& [name, accuracy] : result_.floor_accuracy) f[name] = accuracy;
  }
  j["wifi_words"] = result_.wifi_words;
  j["wifi_map_scans"] = result_.wifi_map_scans;
  j["wifi_tree_scans"] = result_.wifi_tree_scans;
  if (options_.pipeline.evaluation.online_rssi_offset) {
    nlohmann::ordered_json& offsets = j["query_rssi_offsets_db"];
    offsets = nlohmann::ordered_json::array();
    for (const SessionRssiOffset& o : result_.query_rssi_offsets) {
      offsets.push_back({{"session", o.session}, {"offset_db", o.offset_db}});
    }
  }
  j["visual_words"] = result_.visual_words;
  j["query_time_ms"] = result_.query_time_ms;
  result_.wall_time_s = clock_->Seconds() - started_s_;
  j["wall_time_s"] = result_.wall_time_s;
  std::vector<std::string> inputs = {options_.map_path};
  if (options_.query_path != options_.map_path) inputs.push_back(options_.query_path);
  j["run"] = io::RunObject(options_.provenance, inputs, std::nullopt,
                           io::ConfigFingerprint(options_.pipeline));
  result_.json = j.dump(2) + "\n";

  // Numbers in shortest round-trip form; error_m is numeric (inf for another floor, empty for a
  // rejection) and status says which case it is.
  std::ostringstream csv;
  csv << "query,x_m,y_m,floor,match,match_x_m,match_y_m,match_floor,error_m,status,"
         "match_probability,new_place_probability,best_mapped_place,best_mapped_probability,"
         "best_mapped_log_odds,nearest_place_m";
  // Each baseline's error on the same query, in error_m's form: per-query comparisons.
  for (const auto& [name, b] : result_.baselines) csv << ',' << name << "_error_m";
  csv << '\n';
  auto error_cell = [](double e) { return std::isnan(e) ? std::string() : ShortestNumber(e); };
  for (size_t i = 0; i < result_.queries.size(); ++i) {
    const auto& q = result_.queries[i];
    const int64_t match = result_.matches[i];
    csv << i << ',' << ShortestNumber(q.x_m) << ',' << ShortestNumber(q.y_m) << ',' << q.floor
        << ',' << match;
    if (const fabmap::Estimate& a = result_.answers[i]; a.located) {
      csv << ',' << ShortestNumber(a.x_m) << ',' << ShortestNumber(a.y_m) << ',' << a.floor;
    } else {
      csv << ",,,";
    }
    const double e = m.errors_m[i];
    csv << ',' << error_cell(e) << ','
        << (std::isnan(e)   ? "rejected"
            : std::isinf(e) ? "other_floor"
                            : "located")
        << ',' << ShortestNumber(result_.match_probability[i]) << ','
        << ShortestNumber(result_.new_place_probability[i]) << ',' << result_.best_mapped_place[i]
        << ',';
    if (result_.best_mapped_place[i] >= 0) {
      csv << ShortestNumber(result_.best_mapped_probability[i]) << ','
          << ShortestNumber(result_.best_mapped_log_odds[i]);
    } else {
      csv << ',';
    }
    csv << ',' << ShortestNumber(nearest[i]);
    for (const auto& [name, b] : result_.baselines) csv << ',' << error_cell(b.errors_m[i]);
    csv << '\n';
  }
  // Precision-recall: one row per distinct best-mapped-place posterior, highest first.
  std::ostringstream pr;
  pr << "threshold,accepted";
  for (double d : kDistancesM) {
    const std::string k = ShortestNumber(d);
    pr << ",correct_within_" << k << "m,precision_" << k << "m,recall_" << k << "m";
  }
  pr << '\n';
  for (const fabmap::PrecisionRecallPoint& p : result_.precision_recall) {
    pr << ShortestNumber(p.threshold) << ',' << p.accepted;
    for (size_t k = 0; k < kDistancesM.size(); ++k) {
      pr << ',' << p.correct[k] << ',' << ShortestNumber(p.precision[k]) << ','
         << ShortestNumber(p.recall[k]);
    }
    pr << '\n';
  }
  return out_->Write(
      {{"evaluation.json", result_.json}, {"queries.csv", csv.str()}, {"pr_curve.csv", pr.str()}});
}

StatusOr<EvaluationResult> EvaluationSession::Run() {
  RATSLAM_RETURN_IF_ERROR(Load());
  RATSLAM_RETURN_IF_ERROR(Prepare());
  RATSLAM_RETURN_IF_ERROR(Localise());
  RATSLAM_RETURN_IF_ERROR(WriteOutputs());
  return result_;
}

}  // namespace ratslam::session
