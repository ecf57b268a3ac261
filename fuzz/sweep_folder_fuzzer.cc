// A sweep's folder as `ratslam sweep collect` (and `sweep run`, `sweep slurm`) reads it:
// plan.json, two runs' status.json and summary.json, and search.json, fuzzed as one input whose
// parts are separated by a line "%%". A plan that reads has tasks in order, each of a point and a
// data set the plan has; collecting either fails naming a file of the folder or accounts for
// every task once, ranks only finite objectives and names as best a point no other beats.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "fuzz/fuzz_support.h"
#include "sweep/sweep.h"

namespace ratslam::fuzz {
namespace {

const char* const kFiles[] = {"plan.json",
                              "runs/00000/status.json",
                              "runs/00000/summary.json",
                              "runs/00001/status.json",
                              "runs/00001/summary.json",
                              "search.json"};

// plan.json as `sweep plan` writes it for a two-point sweep of one data set (made by the sweep
// library itself, so the seeds follow its format).
std::string PlanText(const std::string& objective, const std::string& aggregate,
                     const std::string& goal) {
  namespace fs = std::filesystem;
  const fs::path root = Scratch() / "seed_plan";
  fs::remove_all(root);
  fs::create_directories(root / "data");
  std::ofstream(root / "base.toml") << "[fused]\nrecency_s = 30.0\n";
  std::ofstream(root / "sweep.toml")
      << "[sweep]\nbase_config = \"base.toml\"\nobjective = \"" << objective
      << "\"\nmetrics = [\"templates\", \"finished\", \"match_rate_within_m.5\"]\naggregate = \""
      << aggregate << "\"\ngoal = \"" << goal
      << "\"\n[[datasets]]\ndata = [\"data\"]\n[parameters]\n\"fused.recency_s\" = [10, 20.5]\n";
  StatusOr<sweep::SweepSpec> spec = sweep::LoadSweepFile((root / "sweep.toml").string());
  if (!spec.ok()) InvariantFailed("seed sweep file: " + spec.status().message());
  StatusOr<sweep::Plan> plan = sweep::MakePlan(*spec);
  if (!plan.ok()) InvariantFailed("seed plan: " + plan.status().message());
  const Status written = sweep::WritePlan(*plan, (root / "out").string());
  if (!written.ok()) InvariantFailed("seed plan not written: " + written.message());
  std::ifstream in(root / "out" / "plan.json", std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string StatusJson(const std::string& status, int exit_code, double wall_s) {
  return nlohmann::json{{"status", status},
                        {"exit_code", exit_code},
                        {"wall_s", wall_s},
                        {"error", status == "ok" ? "" : "replay: no such data set"},
                        {"program", "/usr/bin/ratslam"},
                        {"host", "node1"}}
      .dump();
}

std::string Join(const std::vector<std::string>& parts) {
  std::string input;
  for (size_t i = 0; i < parts.size(); ++i) input += (i ? "\n%%\n" : "") + parts[i];
  return input;
}

}  // namespace

std::vector<std::string> FuzzSeeds() {
  const std::string summary =
      R"({"templates": 12, "map_ate_m": 1.5, "finished": true, "match_rate_within_m": {"5": 0.75}})";
  const std::string other =
      R"({"templates": 30, "map_ate_m": 0.5, "finished": false, "match_rate_within_m": {"5": 0.5}})";
  return {
      Join({PlanText("map_ate_m", "mean", "minimize"), StatusJson("ok", 0, 2.5), summary,
            StatusJson("ok", 0, 3.0), other}),
      Join({PlanText("map_ate_m + 0.1 * templates", "worst", "maximize"), StatusJson("ok", 0, 2.5),
            summary, StatusJson("failed", 1, 0.25), "", "{\"rounds\": []}"}),
      Join({PlanText("match_rate_within_m.5", "mean", "maximize"), StatusJson("timeout", 137, 30),
            "", "{\"status\": \"ok\", \"exit"})};
}

}  // namespace ratslam::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ratslam;
  const std::vector<std::string> parts = fuzz::SplitParts(data, size, "\n%%\n");
  const std::string folder =
      fuzz::WriteScratchFolder("sweep", parts, {std::begin(fuzz::kFiles), std::end(fuzz::kFiles)});
  auto names_the_folder = [&](const Status& status) {
    return status.message().rfind(folder, 0) == 0;
  };
  StatusOr<sweep::Plan> plan = sweep::ReadPlan(folder);
  if (!plan.ok()) {
    if (!names_the_folder(plan.status())) {
      fuzz::InvariantFailed("plan error does not name the file: " + plan.status().message());
    }
    return 0;
  }
  for (size_t i = 0; i < plan->tasks.size(); ++i) {
    const sweep::Task& t = plan->tasks[i];
    if (t.index != static_cast<int>(i) || t.point < 0 || t.point >= plan->points || t.dataset < 0 ||
        t.dataset >= static_cast<int>(plan->spec.datasets.size())) {
      fuzz::InvariantFailed("a plan read with a task out of order or out of range");
    }
  }
  if (plan->points > 100000) return 0;  // large plans are valid; collecting them is slow
  StatusOr<sweep::CollectReport> report = sweep::Collect(folder);
  if (!report.ok()) {
    if (!names_the_folder(report.status())) {
      fuzz::InvariantFailed("collect error does not name a file: " + report.status().message());
    }
    return 0;
  }
  const sweep::CollectReport& r = *report;
  if (r.ok + r.failed + r.pending + r.eliminated != static_cast<int>(plan->tasks.size())) {
    fuzz::InvariantFailed("collect did not account for every task once");
  }
  if (r.points.size() != static_cast<size_t>(plan->points)) {
    fuzz::InvariantFailed("collect did not report every point");
  }
  const bool minimize = plan->spec.goal == "minimize";
  for (const sweep::PointSummary& p : r.points) {
    if (p.objective && !std::isfinite(*p.objective)) {
      fuzz::InvariantFailed("a point ranked by a non-finite objective");
    }
    if (!std::isfinite(p.mean_wall_s)) fuzz::InvariantFailed("a non-finite mean wall time");
    if (p.objective && r.best_point &&
        (minimize ? *p.objective < r.best_objective : *p.objective > r.best_objective)) {
      fuzz::InvariantFailed("a point beats the best");
    }
  }
  if (r.best_point) {
    if (*r.best_point < 0 || *r.best_point >= plan->points ||
        r.points[static_cast<size_t>(*r.best_point)].objective != r.best_objective) {
      fuzz::InvariantFailed("the best point is not a ranked point");
    }
    if (!std::filesystem::exists(std::filesystem::path(folder) / "best.toml")) {
      fuzz::InvariantFailed("a best point without best.toml");
    }
  }
  std::ifstream in(std::filesystem::path(folder) / "results.json");
  const nlohmann::json results = nlohmann::json::parse(in, nullptr, false);
  if (!results.is_object() || !results.contains("runs") ||
      results["runs"].size() != plan->tasks.size()) {
    fuzz::InvariantFailed("results.json does not hold one entry per task");
  }
  return 0;
}
