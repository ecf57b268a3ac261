// Parameter sweeps: a TOML sweep file (configs/README.md, "Sweeps") is planned into a table of
// tasks, each task a replay run in its own process with its own folder; a sweep resumes after
// any interruption, and `Collect` gathers every run's metrics, aggregates an objective over the
// data sets and writes the best configuration.
//
// Plan folder layout: plan.json (the spec, the resolved base configuration and every task),
// tasks.csv (the same table for people), runs/NNNNN/ (config.toml, the run's outputs,
// stderr.txt, and status.json once the run has ended; a task without status.json is pending).
#ifndef RATSLAM_SWEEP_SWEEP_H_
#define RATSLAM_SWEEP_SWEEP_H_

#include <atomic>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/progress.h"
#include "common/status.h"
#include "fusion/replay_pipeline.h"

namespace ratslam::sweep {

// One varied configuration key and the values it takes.
struct Parameter {
  std::string key;                  // "section.key" of the configuration
  std::vector<std::string> values;  // TOML literals: the grid, or the choices of a random draw
  // Random draws of a continuous range (values empty): uniform in [lo, hi], or log-uniform.
  bool log_scale = false;
  bool integer = false;  // the range's ends were integers: draws are rounded
  double lo = 0.0, hi = 0.0;
  int line = 0;  // in the sweep file
};

struct SweepSpec {
  std::string source;            // the sweep file, for messages
  std::string base_config_text;  // resolved base configuration (TOML)
  // replay (metrics from summary.json) or evaluate (the FABMAP benchmark: each data-set entry
  // is [map] or [map, query]; metrics from evaluation.json).
  std::string command = "replay";
  std::vector<std::vector<std::string>> datasets;  // each run replays one entry (its sessions)
  std::vector<Parameter> parameters;
  std::string method = "grid";  // grid: every combination; random: `samples` seeded draws
  int samples = 0;
  uint64_t seed = 1;
  // Which tasks run: all, or successive halving over the data sets (the best 1/halving_rate of
  // the points go on to halving_rate times as many data sets; DIR/search.json says which).
  std::string search = "all";
  double halving_rate = 3.0;
  std::vector<std::string> metrics;  // dotted keys into summary.json ("map_ate_m", ...)
  std::string objective;             // one of the metrics
  std::string aggregate = "mean";    // over the data sets: mean or worst
  std::string goal = "minimize";     // or maximize
  double timeout_s = 0.0;            // per run; 0: none
  bool keep_all = false;             // keep every output file (else summary, config, trajectory)
};

// Reads a sweep file; relative paths (base config, data sets, globs) are relative to its folder.
// Errors name the file and line.
StatusOr<SweepSpec> LoadSweepFile(const std::string& path);

struct Task {
  int index = 0;
  int point = 0;                                               // the parameter combination
  int dataset = 0;                                             // index into SweepSpec::datasets
  std::vector<std::pair<std::string, std::string>> overrides;  // key, TOML literal
};

struct Plan {
  SweepSpec spec;
  int points = 0;
  std::vector<Task> tasks;  // point-major: all data sets of point 0, then of point 1, ...
};

// Expands the spec (grid or seeded random draws) and checks every expanded configuration; a bad
// key or value fails with the sweep file's line. The same spec always gives the same plan.
StatusOr<Plan> MakePlan(const SweepSpec& spec);
// The configuration of one task: the base with the task's overrides.
StatusOr<fusion::PipelineOptions> TaskConfig(const Plan& plan, const Task& task);

// Writes plan.json and tasks.csv into `dir` (created). Refuses a folder holding a different plan.
Status WritePlan(const Plan& plan, const std::string& dir);
StatusOr<Plan> ReadPlan(const std::string& dir);

// How a task ended (runs/NNNNN/status.json).
struct TaskOutcome {
  int index = 0;
  std::string status;  // "ok", "failed", "timeout", or "pending" (never ended)
  int exit_code = 0;   // the run's exit status, or 128 + signal
  double wall_s = 0.0;
  std::string error;  // last line the run wrote to stderr, when it failed
  // Provenance: the program that ran the task and the machine it ran on.
  std::string program;
  std::string host;
};

struct RunOptions {
  std::string program;  // the ratslam executable to run tasks with
  int jobs = 1;         // tasks at once
  ProgressSink* progress = nullptr;
  const std::atomic<bool>* stop_requested = nullptr;  // stop starting; end running tasks
};

struct RunReport {
  int done = 0, failed = 0, skipped = 0, pending = 0;
};

// Runs every task of the plan in `dir` without status.json, `jobs` at a time, each as
// `program replay ...` in its own process group. A stopped or interrupted task leaves no
// status.json (it runs again next time); a failure or timeout is recorded and the others go on.
StatusOr<RunReport> RunSweep(const std::string& dir, const RunOptions& options);
// Runs one task (what a cluster array job calls); a task already ended is not run again.
StatusOr<TaskOutcome> RunTask(const std::string& dir, int index, const std::string& program);

// Runs tasks [first, first + count) of the plan one after another (an array job's share when a
// sweep has more tasks than the cluster allows array elements); the outcome of each.
StatusOr<std::vector<TaskOutcome>> RunTasks(const std::string& dir, int first, int count,
                                            const std::string& program);

// A Slurm job array over a plan's pending tasks, and a collect job that runs after it whatever
// its tasks' outcome (afterany).
struct SlurmOptions {
  std::string program;  // the ratslam executable the jobs run (an absolute path)
  std::string partition, time, mem;
  int max_parallel = 0;                  // array tasks at once (%K); 0: no limit
  int chunk = 1;                         // plan tasks per array element
  std::vector<std::string> sbatch_args;  // extra "#SBATCH" lines, e.g. "--account=x"
};
struct SlurmJobs {
  std::string array_script, collect_script;  // paths, in DIR/slurm/
  std::string array_spec;                    // the --array value, e.g. "0-9,12%2"
  std::string array_job, collect_job;        // job ids once submitted
};
// Writes DIR/slurm/array.sh and DIR/slurm/collect.sh (logs go to DIR/slurm/logs/). Fails when
// nothing is pending.
StatusOr<SlurmJobs> WriteSlurmScripts(const std::string& dir, const SlurmOptions& options);
// Submits both scripts with sbatch (on PATH) and fills in the job ids.
Status SubmitSlurm(SlurmJobs* jobs);

// The recorded outcome of every task (pending ones included).
StatusOr<std::vector<TaskOutcome>> ReadOutcomes(const std::string& dir);

// One parameter combination as collected.
struct PointSummary {
  int point = 0;
  std::vector<std::pair<std::string, std::string>> overrides;
  std::optional<double> objective;  // aggregated; none unless every run of the point succeeded
  double mean_wall_s = 0.0;         // over its runs that ended
  int runs_ok = 0;
};

// Set by `sweep run` in the environment of each run it starts, to its own pid: the run (the
// `ratslam` program) then asks to be sent SIGTERM when that parent dies, and stops at once if it
// is already gone, so that no run outlives a killed runner.
inline constexpr const char* kEndWithParentVariable = "RATSLAM_END_WITH_PARENT";

struct CollectReport {
  std::vector<PointSummary> points;
  int ok = 0, failed = 0, pending = 0;
  int eliminated = 0;            // never run: their point was dropped by successive halving
  int ok_without_objective = 0;  // runs that succeeded but whose summary lacks the objective
  std::optional<int> best_point;
  double best_objective = 0.0;
};

// Writes results.csv and results.json (every task: parameters, metrics, status, error, wall
// time), points.csv (each parameter combination with its aggregated objective) and best.toml
// (the best point's full configuration) into `dir`. When the best point's configuration cannot be
// made (a damaged plan), the other three are written and the error names plan.json.
StatusOr<CollectReport> Collect(const std::string& dir);

}  // namespace ratslam::sweep

#endif  // RATSLAM_SWEEP_SWEEP_H_
