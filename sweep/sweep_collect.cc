// Collecting a sweep's results: metrics, objectives, the ranking and best.toml (sweep/sweep.h).
#include <fcntl.h>
#include <glob.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "common/file_util.h"
#include "common/output_guard.h"
#include "common/random.h"
#include "common/text_file.h"
#include "common/toml_binder.h"
#include "io/config.h"
#include "io/run_outputs.h"
#include "session/evaluation_session.h"
#include "sweep/sweep.h"
#include "sweep/sweep_internal.h"

extern char** environ;

namespace ratslam::sweep {
namespace fs = std::filesystem;
using json = nlohmann::json;

std::optional<double> RunObjective(const Plan& plan, const std::string& dir, int index) {
  StatusOr<TaskOutcome> o = ReadOutcome(dir, index);
  if (!o.ok() || o->status != "ok") return std::nullopt;
  StatusOr<std::string> text = ReadRegularFile(RunFolder(dir, index) + "/" + MetricsFile(plan.spec),
                                               "run metrics", size_t{1} << 26);
  if (!text.ok()) return std::nullopt;
  return ObjectiveOf(json::parse(*text, nullptr, false), plan.spec.objective);
}

namespace {

std::string Format(std::optional<double> v) { return v ? schema::TomlNumber(*v) : std::string(); }

}  // namespace

StatusOr<CollectReport> Collect(const std::string& dir) {
  StatusOr<Plan> plan = ReadPlan(dir);
  if (!plan.ok()) return plan.status();
  const SweepSpec& spec = plan->spec;
  CollectReport report;
  // After a finished successive halving, a task that never ran belongs to an eliminated point.
  const bool halving_done = PathExists(fs::path(dir) / "search.json");
  // Data sets by number and by their paths (a number alone sent readers to plan.json).
  std::string csv = "index,point,dataset,data,status,exit_code,wall_s";
  for (const Parameter& p : spec.parameters) {
    csv += ',';
    csv += CsvField(p.key);
  }
  for (const std::string& m : spec.metrics) {
    csv += ',';
    csv += CsvField(m);
  }
  csv += ",error\n";
  json runs = json::array();
  // Per point: the objective of each data set (nullopt when its run did not succeed).
  std::vector<std::vector<std::optional<double>>> objectives(plan->points);
  std::vector<std::pair<double, int>> wall(plan->points);  // sum of wall times, runs
  for (const Task& t : plan->tasks) {
    StatusOr<TaskOutcome> o = ReadOutcome(dir, t.index);
    if (!o.ok()) return o.status();
    json summary;
    if (o->status == "ok") {
      ++report.ok;
      StatusOr<std::string> text = ReadRegularFile(
          RunFolder(dir, t.index) + "/" + MetricsFile(spec), "run metrics", size_t{1} << 26);
      if (text.ok()) summary = json::parse(*text, nullptr, false);
    } else if (o->status == "pending" && halving_done) {
      o->status = "eliminated";
      ++report.eliminated;
    } else if (o->status == "pending") {
      ++report.pending;
    } else {
      ++report.failed;
    }
    std::string data;
    for (const std::string& d : spec.datasets[t.dataset]) data += (data.empty() ? "" : ";") + d;
    csv += std::to_string(t.index) + "," + std::to_string(t.point) + "," +
           std::to_string(t.dataset) + "," + CsvField(data) + "," + o->status + "," +
           std::to_string(o->exit_code) + "," + schema::TomlNumber(o->wall_s);
    json parameters = json::object();
    for (const auto& [key, value] : t.overrides) {
      csv += ',';
      csv += CsvField(value);
      parameters[key] = value;
    }
    json metrics = json::object();
    for (const std::string& m : spec.metrics) {
      const std::optional<double> v = o->status == "ok" ? Metric(summary, m) : std::nullopt;
      csv += ',';
      csv += Format(v);
      metrics[m] = v ? json(*v) : json(nullptr);
    }
    csv += ',';
    csv += CsvField(o->error) + "\n";
    objectives[t.point].push_back(o->status == "ok" ? ObjectiveOf(summary, spec.objective)
                                                    : std::nullopt);
    if (o->status == "ok" && !objectives[t.point].back()) ++report.ok_without_objective;
    if (o->status == "ok" || o->status == "failed" || o->status == "timeout") {
      wall[t.point].first += o->wall_s;
      ++wall[t.point].second;
    }
    runs.push_back(
        {{"index", t.index},
         {"point", t.point},
         {"data", spec.datasets[t.dataset]},
         {"parameters", parameters},
         {"metrics", metrics},
         {"status", o->status},
         {"exit_code", o->exit_code},
         {"wall_s", o->wall_s},
         {"error", o->error},
         {"program", o->program},
         {"host", o->host},
         {"config_fingerprint", summary.is_object() && summary.contains("config_fingerprint")
                                    ? summary["config_fingerprint"]
                                    : json()},
         {"folder", RunFolder(dir, t.index)}});
  }
  const bool minimize = spec.goal == "minimize";
  std::string points_csv = "point";
  for (const Parameter& p : spec.parameters) {
    points_csv += ',';
    points_csv += CsvField(p.key);
  }
  points_csv += ",objective,runs_ok\n";
  std::map<int, std::vector<std::pair<std::string, std::string>>> overrides;
  for (const Task& t : plan->tasks) overrides[t.point] = t.overrides;
  for (int p = 0; p < plan->points; ++p) {
    double aggregate = 0.0;
    int ok = 0;
    bool complete = !objectives[p].empty();
    for (const std::optional<double>& v : objectives[p]) {
      if (!v) {
        complete = false;
        continue;
      }
      if (ok == 0 || spec.aggregate == "mean") {
        aggregate = ok == 0 ? *v : aggregate + *v;
      } else {
        aggregate = minimize ? std::max(aggregate, *v) : std::min(aggregate, *v);
      }
      ++ok;
    }
    if (ok > 0 && spec.aggregate == "mean") aggregate /= ok;
    // A point with a failed or missing run is not ranked.
    const std::optional<double> ranked = complete ? std::optional<double>(aggregate) : std::nullopt;
    report.points.push_back(
        {p, overrides[p], ranked, wall[p].second ? wall[p].first / wall[p].second : 0.0, ok});
    points_csv += std::to_string(p);
    for (const auto& [key, value] : overrides[p]) {
      points_csv += ',';
      points_csv += CsvField(value);
    }
    points_csv += ',';
    points_csv += Format(ranked) + "," + std::to_string(ok) + "\n";
    if (complete && (!report.best_point || (minimize ? aggregate < report.best_objective
                                                     : aggregate > report.best_objective))) {
      report.best_point = p;
      report.best_objective = aggregate;
    }
  }
  const json results = {
      {"sweep", spec.source},
      {"objective", spec.objective},
      {"aggregate", spec.aggregate},
      {"goal", spec.goal},
      {"runs", runs},
      {"ok", report.ok},
      {"failed", report.failed},
      {"pending", report.pending},
      {"best_point", report.best_point ? json(*report.best_point) : json()},
      {"best_objective", report.best_point ? json(report.best_objective) : json()}};
  std::vector<std::pair<std::string, std::string>> files = {
      {(fs::path(dir) / "results.csv").string(), csv},
      {(fs::path(dir) / "points.csv").string(), points_csv},
      {(fs::path(dir) / "results.json").string(), results.dump(1) + "\n"}};
  if (report.best_point) {
    const Task* best = nullptr;
    for (const Task& t : plan->tasks) {
      if (t.point == *report.best_point) best = &t;
    }
    StatusOr<fusion::PipelineOptions> config = TaskConfig(*plan, *best);
    if (!config.ok()) return config.status();
    std::string header = "# Best point " + std::to_string(*report.best_point) + " of " +
                         spec.source + ": " + spec.aggregate + " " + spec.objective + " = " +
                         schema::TomlNumber(report.best_objective) + " over " +
                         std::to_string(spec.datasets.size()) + " data set(s)\n";
    for (const auto& [key, value] : best->overrides) header += "#   " + key + " = " + value + "\n";
    files.push_back(
        {(fs::path(dir) / "best.toml").string(), header + "\n" + io::PrintConfig(*config)});
  }
  RATSLAM_RETURN_IF_ERROR(WriteFilesAtomically(files));
  return report;
}

}  // namespace ratslam::sweep
