// Collecting a sweep's results: metrics, objectives, the ranking and best.toml (sweep/sweep.h).

#include <algorithm>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/file_util.h"
#include "common/text_file.h"
#include "common/toml_binder.h"
#include "io/config.h"
#include "sweep/sweep.h"
#include "sweep/sweep_internal.h"

namespace ratslam::sweep {
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

// A succeeded run's metrics file (summary.json or evaluation.json); null when it cannot be read.
json RunMetrics(const std::string& dir, const SweepSpec& spec, int index) {
  StatusOr<std::string> text = ReadRegularFile(RunFolder(dir, index) + "/" + MetricsFile(spec),
                                               "run metrics", size_t{1} << 26);
  return text.ok() ? json::parse(*text, nullptr, false) : json();
}

}  // namespace

std::optional<double> RunObjective(const Plan& plan, const std::string& dir, int index) {
  StatusOr<TaskOutcome> o = ReadOutcome(dir, index);
  if (!o.ok() || o->status != "ok") return std::nullopt;
  const json metrics = RunMetrics(dir, plan.spec, index);
  if (metrics.is_null()) return std::nullopt;
  return ObjectiveOf(metrics, plan.spec.objective);
}

namespace {

std::string Format(std::optional<double> v) { return v ? schema::TomlNumber(*v) : std::string(); }

// What the tasks' runs give: results.csv and results.json's runs (one row and entry per task),
// and per point what the ranking needs.
struct RunTables {
  std::string csv;
  json runs = json::array();
  // Per point: the objective of each data set (nullopt when its run did not succeed).
  std::vector<std::vector<std::optional<double>>> objectives;
  std::vector<std::pair<double, int>> wall;  // per point: sum of wall times, runs that ended
};

std::string ResultsCsvHeader(const SweepSpec& spec) {
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
  return csv + ",error\n";
}

// One task's outcome, counted in `report`, with its run's summary (null unless it succeeded). After
// a finished successive halving, a task that never ran belongs to an eliminated point.
StatusOr<std::pair<TaskOutcome, json>> ReadTask(const std::string& dir, const SweepSpec& spec,
                                                const Task& t, bool halving_done,
                                                CollectReport* report) {
  StatusOr<TaskOutcome> o = ReadOutcome(dir, t.index);
  if (!o.ok()) return o.status();
  json summary;
  if (o->status == "ok") {
    ++report->ok;
    summary = RunMetrics(dir, spec, t.index);
  } else if (o->status == "pending" && halving_done) {
    o->status = "eliminated";
    ++report->eliminated;
  } else if (o->status == "pending") {
    ++report->pending;
  } else {
    ++report->failed;
  }
  return std::pair<TaskOutcome, json>{std::move(*o), std::move(summary)};
}

// Adds the task's row to results.csv and its entry to the runs, and its objective and wall time
// to its point's.
void AddTask(const std::string& dir, const SweepSpec& spec, const Task& t, const TaskOutcome& o,
             const json& summary, CollectReport* report, RunTables* tables) {
  std::string& csv = tables->csv;
  std::string data;
  for (const std::string& d : spec.datasets[t.dataset]) data += (data.empty() ? "" : ";") + d;
  csv += std::to_string(t.index) + "," + std::to_string(t.point) + "," + std::to_string(t.dataset) +
         "," + CsvField(data) + "," + o.status + "," + std::to_string(o.exit_code) + "," +
         schema::TomlNumber(o.wall_s);
  json parameters = json::object();
  for (const auto& [key, value] : t.overrides) {
    csv += ',';
    csv += CsvField(value);
    parameters[key] = value;
  }
  json metrics = json::object();
  for (const std::string& m : spec.metrics) {
    const std::optional<double> v = o.status == "ok" ? Metric(summary, m) : std::nullopt;
    csv += ',';
    csv += Format(v);
    metrics[m] = v ? json(*v) : json(nullptr);
  }
  csv += ',';
  csv += CsvField(o.error) + "\n";
  std::vector<std::optional<double>>& objectives = tables->objectives[t.point];
  objectives.push_back(o.status == "ok" ? ObjectiveOf(summary, spec.objective) : std::nullopt);
  if (o.status == "ok" && !objectives.back()) ++report->ok_without_objective;
  if (o.status == "ok" || o.status == "failed" || o.status == "timeout") {
    tables->wall[t.point].first += o.wall_s;
    ++tables->wall[t.point].second;
  }
  tables->runs.push_back(
      {{"index", t.index},
       {"point", t.point},
       {"data", spec.datasets[t.dataset]},
       {"parameters", parameters},
       {"metrics", metrics},
       {"status", o.status},
       {"exit_code", o.exit_code},
       {"wall_s", o.wall_s},
       {"error", o.error},
       {"program", o.program},
       {"host", o.host},
       {"config_fingerprint", summary.is_object() && summary.contains("config_fingerprint")
                                  ? summary["config_fingerprint"]
                                  : json()},
       {"folder", RunFolder(dir, t.index)}});
}

StatusOr<RunTables> CollectRuns(const std::string& dir, const Plan& plan, CollectReport* report) {
  const bool halving_done = PathExists(fs::path(dir) / "search.json");
  RunTables tables;
  tables.csv = ResultsCsvHeader(plan.spec);
  tables.objectives.resize(plan.points);
  tables.wall.resize(plan.points);
  for (const Task& t : plan.tasks) {
    StatusOr<std::pair<TaskOutcome, json>> task = ReadTask(dir, plan.spec, t, halving_done, report);
    if (!task.ok()) return task.status();
    AddTask(dir, plan.spec, t, task->first, task->second, report, &tables);
  }
  return tables;
}

// A point's objectives over its data sets, aggregated (the mean, or the worst for the goal); the
// ranking takes it only when every run gave one (a point with a failed or missing run is not
// ranked).
struct PointAggregate {
  double value = 0.0;  // over the runs that gave an objective
  int ok = 0;          // those runs
  bool complete = false;
};

PointAggregate Aggregate(const SweepSpec& spec, const std::vector<std::optional<double>>& values) {
  const bool minimize = spec.goal == "minimize";
  PointAggregate a;
  a.complete = !values.empty();
  for (const std::optional<double>& v : values) {
    if (!v) {
      a.complete = false;
      continue;
    }
    if (a.ok == 0 || spec.aggregate == "mean") {
      a.value = a.ok == 0 ? *v : a.value + *v;
    } else {
      a.value = minimize ? std::max(a.value, *v) : std::min(a.value, *v);
    }
    ++a.ok;
  }
  if (a.ok > 0 && spec.aggregate == "mean") a.value /= a.ok;
  return a;
}

// Ranks the points into `report` (its points and best point); returns points.csv.
std::string RankPoints(const Plan& plan, const RunTables& tables, CollectReport* report) {
  const SweepSpec& spec = plan.spec;
  const bool minimize = spec.goal == "minimize";
  std::string csv = "point";
  for (const Parameter& p : spec.parameters) {
    csv += ',';
    csv += CsvField(p.key);
  }
  csv += ",objective,runs_ok\n";
  std::map<int, std::vector<std::pair<std::string, std::string>>> overrides;
  for (const Task& t : plan.tasks) overrides[t.point] = t.overrides;
  for (int p = 0; p < plan.points; ++p) {
    const PointAggregate a = Aggregate(spec, tables.objectives[p]);
    const std::optional<double> ranked = a.complete ? std::optional<double>(a.value) : std::nullopt;
    const auto& [wall_s, ended] = tables.wall[p];
    report->points.push_back({p, overrides[p], ranked, ended ? wall_s / ended : 0.0, a.ok});
    csv += std::to_string(p);
    for (const auto& [key, value] : overrides[p]) {
      csv += ',';
      csv += CsvField(value);
    }
    csv += ',';
    csv += Format(ranked) + "," + std::to_string(a.ok) + "\n";
    if (a.complete && (!report->best_point || (minimize ? a.value < report->best_objective
                                                        : a.value > report->best_objective))) {
      report->best_point = p;
      report->best_objective = a.value;
    }
  }
  return csv;
}

// best.toml: the best point's whole configuration, its overrides in the header.
StatusOr<std::string> BestToml(const std::string& dir, const Plan& plan,
                               const CollectReport& report) {
  const SweepSpec& spec = plan.spec;
  const Task* best = nullptr;
  for (const Task& t : plan.tasks) {
    if (t.point == *report.best_point) best = &t;
  }
  StatusOr<fusion::PipelineOptions> config = TaskConfig(plan, *best);
  if (!config.ok()) {  // the plan's base configuration or parameters, edited or damaged
    return Status::Error((fs::path(dir) / "plan.json").string() + ": best point " +
                         std::to_string(*report.best_point) + ": " + config.status().message());
  }
  std::string header = "# Best point " + std::to_string(*report.best_point) + " of " + spec.source +
                       ": " + spec.aggregate + " " + spec.objective + " = " +
                       schema::TomlNumber(report.best_objective) + " over " +
                       std::to_string(spec.datasets.size()) + " data set(s)\n";
  for (const auto& [key, value] : best->overrides) header += "#   " + key + " = " + value + "\n";
  return header + "\n" + io::PrintConfig(*config);
}

}  // namespace

StatusOr<CollectReport> Collect(const std::string& dir) {
  StatusOr<Plan> plan = ReadPlan(dir);
  if (!plan.ok()) return plan.status();
  const SweepSpec& spec = plan->spec;
  CollectReport report;
  StatusOr<RunTables> tables = CollectRuns(dir, *plan, &report);
  if (!tables.ok()) return tables.status();
  const std::string points_csv = RankPoints(*plan, *tables, &report);
  const json results = {
      {"sweep", spec.source},
      {"objective", spec.objective},
      {"aggregate", spec.aggregate},
      {"goal", spec.goal},
      {"runs", tables->runs},
      {"ok", report.ok},
      {"failed", report.failed},
      {"pending", report.pending},
      {"eliminated", report.eliminated},
      {"best_point", report.best_point ? json(*report.best_point) : json()},
      {"best_objective", report.best_point ? json(report.best_objective) : json()}};
  std::vector<std::pair<std::string, std::string>> files = {
      {(fs::path(dir) / "results.csv").string(), tables->csv},
      {(fs::path(dir) / "points.csv").string(), points_csv},
      {(fs::path(dir) / "results.json").string(), results.dump(1) + "\n"}};
  if (report.best_point) {
    StatusOr<std::string> best = BestToml(dir, *plan, report);
    if (!best.ok()) {  // the results are still written
      RATSLAM_RETURN_IF_ERROR(WriteFilesAtomically(files));
      return best.status();
    }
    files.push_back({(fs::path(dir) / "best.toml").string(), *best});
  }
  RATSLAM_RETURN_IF_ERROR(WriteFilesAtomically(files));
  return report;
}

}  // namespace ratslam::sweep
