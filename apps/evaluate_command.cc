// `ratslam evaluate`: the fusion paper's localisation benchmark (sections 5.2-5.3) with FABMAP.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "apps/cli.h"
#include "common/file_util.h"
#include "fusion/fabmap/evaluation.h"
#include "fusion/fabmap/localiser.h"
#include "fusion/fabmap/visual_model.h"
#include "viewer/localisation_figure.h"
#include "viewer/renderer.h"

namespace ratslam {

namespace {

namespace fs = std::filesystem;
using fabmap::EvaluationNode;

// Progress lines on stderr: every tenth of the work.
class StepProgress {
 public:
  StepProgress(std::string what, bool quiet) : what_(std::move(what)), quiet_(quiet) {}
  void Update(size_t done, size_t total) {
    if (quiet_ || total == 0) return;
    const size_t decile = done * 10 / total;
    if (decile != last_) {
      last_ = decile;
      std::fprintf(stderr, "evaluate: %s %zu/%zu\n", what_.c_str(), done, total);
    }
  }

 private:
  std::string what_;
  bool quiet_;
  size_t last_ = static_cast<size_t>(-1);
};

Status VisualWords(const fabmap::TrainedVisualModel& model, std::vector<EvaluationNode>& nodes,
                   std::vector<fabmap::Observation>* words, const std::string& what, bool quiet) {
  FileImageLoader loader;
  StepProgress progress("visual words of " + what, quiet);
  words->clear();
  for (size_t i = 0; i < nodes.size(); ++i) {
    if (nodes[i].image.empty()) {
      return Status::Error(what + " node " + std::to_string(i) + " has no image");
    }
    auto image = loader.Load(nodes[i].image);
    if (!image.ok()) return image.status();
    auto w = fabmap::ImageWords(model, *image);
    if (!w.ok()) return w.status().WithContext(nodes[i].image);
    words->push_back(*std::move(w));
    progress.Update(i + 1, nodes.size());
  }
  return Status::Ok();
}

StatusOr<fabmap::TrainedVisualModel> GetVisualModel(const FabmapSettings& settings,
                                                    const std::string& out, bool quiet) {
  FileImageLoader loader;
  StepProgress progress("training images", quiet);
  auto model = fabmap::LoadOrTrainVisualModel(
      settings.visual_model, settings.features, settings.vocabulary, settings.localiser.chow_liu,
      loader, [&](size_t done, size_t total) { progress.Update(done, total); });
  if (!model.ok()) return model.status();
  if (settings.visual_model.file.empty()) {  // trained here: keep it for later runs
    RATSLAM_RETURN_IF_ERROR(WriteFileAtomically((fs::path(out) / "visual_model.bin").string(),
                                                fabmap::EncodeVisualModel(*model)));
  }
  return model;
}

std::string Key(double d) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", d);
  return text;
}

}  // namespace

int EvaluateCommand(int argc, char** argv) {
  const auto args = ParseArguments(argc, argv, 2, {"--config", "--map", "--query", "--out"});
  if (!args || !args->values.count("--map") || !args->values.count("--query") ||
      !args->values.count("--out")) {
    std::cerr << "usage: ratslam evaluate [--config C] --map M --query Q --out O [--quiet]\n";
    return kExitUsage;
  }
  std::string config_path;
  const auto options = LoadOptions(*args, &config_path);
  if (!options) return kExitError;
  const FabmapSettings& settings = options->sensors.fabmap;
  const std::string map_path = args->values.at("--map");
  const std::string query_path = args->values.at("--query");
  const std::string out = args->values.at("--out");
  const bool quiet = args->quiet;
  auto fail = [](const Status& s) {
    std::cerr << "ratslam evaluate: " << s.message() << "\n";
    return kExitError;
  };
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) return fail(Status::Error(out + ": " + ec.message()));
  const auto started = std::chrono::steady_clock::now();
  Status written =
      WriteFileAtomically((fs::path(out) / "config.toml").string(), PrintConfig(*options));
  if (!written.ok()) return fail(written);

  const fabmap::FabmapMode mode = settings.localiser.localiser.mode;
  const bool vision = fabmap::UsesVision(mode);
  auto map_nodes = fabmap::LoadEvaluationNodes(map_path, true, vision, settings.evaluation);
  if (!map_nodes.ok()) return fail(map_nodes.status());
  std::vector<EvaluationNode> map, queries;
  const bool same = fs::equivalent(map_path, query_path, ec);
  if (same) {
    // One data set: the documented interleaved split by node or by session.
    const auto& nodes = *map_nodes;
    std::vector<int> sessions;
    for (const auto& n : nodes) {
      if (sessions.empty() || sessions.back() != n.session) sessions.push_back(n.session);
    }
    const fabmap::SplitUnit unit = settings.evaluation.split;
    const bool by_session = unit == fabmap::SplitUnit::kSession;
    const auto split = fabmap::InterleavedSplit(by_session ? sessions.size() : nodes.size(),
                                                settings.evaluation.map_fraction);
    size_t session_index = 0;
    for (size_t i = 0; i < nodes.size(); ++i) {
      if (i > 0 && nodes[i].session != nodes[i - 1].session) ++session_index;
      const bool in_map = unit == fabmap::SplitUnit::kFirstSession ? session_index == 0
                          : by_session                             ? split[session_index]
                                                                   : split[i];
      (in_map ? map : queries).push_back(nodes[i]);
    }
  } else {
    map = *std::move(map_nodes);
    auto q = fabmap::LoadEvaluationNodes(query_path, false, vision, settings.evaluation);
    if (!q.ok()) return fail(q.status());
    queries = *std::move(q);
  }
  if (map.empty() || queries.empty()) {
    return fail(Status::Error("no map or no query nodes with ground truth (map " +
                              std::to_string(map.size()) + ", queries " +
                              std::to_string(queries.size()) + ")"));
  }
  if (!quiet) {
    std::fprintf(stderr, "evaluate: mode %s, %zu map nodes, %zu queries\n",
                 fabmap::ToString(mode).c_str(), map.size(), queries.size());
  }

  std::optional<fabmap::TrainedVisualModel> visual;
  std::vector<fabmap::Observation> map_words, query_words;
  if (vision) {
    auto model = GetVisualModel(settings, out, quiet);
    if (!model.ok()) return fail(model.status());
    visual = *std::move(model);
    Status s = VisualWords(*visual, map, &map_words, "map", quiet);
    if (s.ok()) s = VisualWords(*visual, queries, &query_words, "queries", quiet);
    if (!s.ok()) return fail(s);
  }
  std::vector<fabmap::MapNode> map_nodes_for_fabmap;
  for (size_t i = 0; i < map.size(); ++i) {
    fabmap::MapNode n;
    if (vision) n.visual = map_words[i];
    n.wifi = map[i].wifi;
    n.travelled_m = map[i].travelled_m;
    n.time_s = map[i].time_s;
    map_nodes_for_fabmap.push_back(std::move(n));
  }
  auto localiser = fabmap::Localiser::Build(settings.localiser, visual ? &visual->model : nullptr,
                                            map_nodes_for_fabmap);
  if (!localiser.ok()) return fail(localiser.status());

  std::vector<int64_t> matches;
  const auto query_start = std::chrono::steady_clock::now();
  StepProgress progress("queries", quiet);
  for (size_t i = 0; i < queries.size(); ++i) {
    fabmap::Query q;
    if (vision) q.visual = query_words[i];
    q.wifi = queries[i].wifi;
    matches.push_back((*localiser)->Localise(q).best_place);
    progress.Update(i + 1, queries.size());
  }
  const double query_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - query_start)
          .count() /
      static_cast<double>(queries.size());
  const std::vector<double> distances = {2, 5, 10, 20};
  const fabmap::EvaluationMetrics m = fabmap::ComputeMetrics(map, queries, matches, distances);

  nlohmann::ordered_json j;
  j["mode"] = fabmap::ToString(mode);
  j["map"] = map_path;
  j["query"] = query_path;
  j["config"] = config_path;
  j["map_nodes"] = map.size();
  j["queries"] = m.queries;
  j["correct_within_m"] = nlohmann::ordered_json::object();
  j["misplaced_beyond_m"] = nlohmann::ordered_json::object();
  for (size_t k = 0; k < distances.size(); ++k) {
    j["correct_within_m"][Key(distances[k])] = m.correct_within[k];
    j["misplaced_beyond_m"][Key(distances[k])] = m.misplaced_beyond[k];
  }
  j["rejection_rate"] = m.rejection_rate;
  j["floor_mistake_rate"] = m.floor_mistake_rate;
  j["wifi_words"] = (*localiser)->wifi_words();
  j["visual_words"] = visual ? visual->vocabulary.size() : 0u;
  j["query_time_ms"] = query_ms;
  j["wall_time_s"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  written = WriteFileAtomically((fs::path(out) / "evaluation.json").string(), j.dump(2) + "\n");
  if (!written.ok()) return fail(written);

  std::ostringstream csv;
  csv << "query,x_m,y_m,floor,match,match_x_m,match_y_m,match_floor,error_m\n";
  for (size_t i = 0; i < queries.size(); ++i) {
    const auto& q = queries[i];
    csv << i << ',' << q.x_m << ',' << q.y_m << ',' << q.floor << ',' << matches[i];
    if (matches[i] >= 0) {
      const auto& p = map[matches[i]];
      csv << ',' << p.x_m << ',' << p.y_m << ',' << p.floor;
    } else {
      csv << ",,,";
    }
    const double e = m.errors_m[i];
    csv << ','
        << (std::isnan(e)   ? std::string("rejected")
            : std::isinf(e) ? "other_floor"
                            : Key(e))
        << '\n';
  }
  written = WriteFileAtomically((fs::path(out) / "queries.csv").string(), csv.str());
  if (!written.ok()) return fail(written);
  const Scene figure = LocalisationCurvesScene({{fabmap::ToString(mode), m.errors_m}},
                                               "FABMAP " + fabmap::ToString(mode) + ": " +
                                                   std::to_string(m.queries) + " queries, " +
                                                   std::to_string(map.size()) + " mapped places");
  written = RenderToPng(figure, (fs::path(out) / "localisation.png").string());
  if (!written.ok()) return fail(written);

  std::printf("%-10s %6s %6s %6s %6s | %6s %6s %6s %6s | %6s %6s\n", "mode", "c2", "c5", "c10",
              "c20", "m2", "m5", "m10", "m20", "reject", "floor");
  std::printf("%-10s", fabmap::ToString(mode).c_str());
  for (double r : m.correct_within) std::printf(" %6.1f", 100 * r);
  std::printf(" |");
  for (double r : m.misplaced_beyond) std::printf(" %6.1f", 100 * r);
  std::printf(" | %6.1f %6.1f\n", 100 * m.rejection_rate, 100 * m.floor_mistake_rate);
  return kExitOk;
}

}  // namespace ratslam
