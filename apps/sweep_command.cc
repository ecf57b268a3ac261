// `ratslam sweep plan|run|task|collect`: the command-line face of ratslam::sweep.
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "apps/cli.h"
#include "apps/progress.h"
#include "render/renderer.h"
#include "sweep/sweep.h"
#include "viewer/sweep_figures.h"

namespace ratslam::apps {
namespace {

std::atomic<bool> g_sweep_stop{false};
extern "C" void OnSweepSignal(int) { g_sweep_stop.store(true); }

// The ratslam executable running now: sweeps start their tasks with the same program.
std::string ThisProgram() {
  char buffer[4096];
  const ssize_t n = readlink("/proc/self/exe", buffer, sizeof buffer - 1);
  return n > 0 ? std::string(buffer, static_cast<size_t>(n)) : std::string("ratslam");
}

// The sweep's figures from its collected points, into DIR/plots/, in the formats --format asks
// for (PNG by default).
Status DrawSweepPlots(const std::string& dir, const sweep::CollectReport& report,
                      const Arguments& args) {
  StatusOr<sweep::Plan> plan = sweep::ReadPlan(dir);
  if (!plan.ok()) return plan.status();
  viewer::SweepFigureData data;
  data.title = std::filesystem::path(plan->spec.source).filename().string();
  data.objective = plan->spec.aggregate + " " + plan->spec.objective;
  data.minimize = plan->spec.goal == "minimize";
  for (const sweep::Parameter& p : plan->spec.parameters) data.keys.push_back(p.key);
  for (const sweep::PointSummary& p : report.points) {
    viewer::SweepFigurePoint point;
    for (const auto& [key, value] : p.overrides) point.values.push_back(value);
    point.objective = p.objective;
    point.mean_wall_s = p.mean_wall_s;
    if (report.best_point && *report.best_point == p.point) {
      data.best = static_cast<int>(data.points.size());
    }
    data.points.push_back(point);
  }
  const std::string plots = dir + "/plots";
  std::error_code ec;
  std::filesystem::create_directories(plots, ec);
  if (ec) return Status::Error(plots + ": cannot create folder: " + ec.message());
  auto draw = [&](const char* name, const std::function<render::Scene(int)>& build) {
    return WriteCommandFigure(args, plots + "/" + name, build);
  };
  if (!data.keys.empty()) {
    RATSLAM_RETURN_IF_ERROR(draw("objective_by_parameter.png",
                                 [&](int w) { return viewer::SweepParameterScene(data, w); }));
  }
  if (data.keys.size() >= 2) {
    RATSLAM_RETURN_IF_ERROR(
        draw("heatmap.png", [&](int w) { return viewer::SweepHeatmapScene(data, 0, 1, w); }));
  }
  return draw("pareto.png", [&](int w) { return viewer::SweepParetoScene(data, w); });
}

int Fail(const Status& s) {
  std::cerr << MessagePrefix() << s.message() << "\n";
  return kExitError;
}

}  // namespace

int SweepPlanCommand(const Arguments& parsed) {
  const Arguments* args = &parsed;
  const std::string& target = args->positional[0];
  StatusOr<sweep::SweepSpec> spec = sweep::LoadSweepFile(target);
  if (!spec.ok()) return Fail(spec.status());
  StatusOr<sweep::Plan> plan = sweep::MakePlan(*spec);
  if (!plan.ok()) return Fail(plan.status());
  Status written = sweep::WritePlan(*plan, args->values.at("--out"));
  if (!written.ok()) return Fail(written);
  std::cout << plan->tasks.size() << " tasks (" << plan->points << " points x "
            << spec->datasets.size() << " data sets) in " << args->values.at("--out") << "\n";
  return kExitOk;
}

int SweepRunCommand(const Arguments& parsed) {
  const Arguments* args = &parsed;
  const std::string& target = args->positional[0];
  sweep::RunOptions options;
  options.program = ThisProgram();
  if (args->Has("--jobs")) options.jobs = static_cast<int>(args->Whole("--jobs"));
  ProgressPrinter progress(stderr, args->quiet);
  options.progress = &progress;
  options.stop_requested = &g_sweep_stop;
  std::signal(SIGINT, OnSweepSignal);
  std::signal(SIGTERM, OnSweepSignal);
  StatusOr<sweep::RunReport> report = sweep::RunSweep(target, options);
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  if (!report.ok()) return Fail(report.status());
  if (!args->quiet) {
    std::cout << report->done << " run, " << report->skipped << " already done, " << report->failed
              << " failed, " << report->pending << " pending\n";
  }
  if (report->pending > 0) return kExitInterrupted;
  return report->failed > 0 ? kExitError : kExitOk;
}

int SweepTaskCommand(const Arguments& parsed) {
  const Arguments* args = &parsed;
  const std::string& target = args->positional[0];
  int64_t index = -1;
  if (args->Has("--index")) {
    index = args->Whole("--index");
  } else {
    for (const char* variable : {"SLURM_ARRAY_TASK_ID", "PBS_ARRAY_INDEX", "SGE_TASK_ID"}) {
      const char* value = std::getenv(variable);
      if (!value) continue;
      auto i = ParseInteger(variable, value, 0, 1 << 30);
      if (!i) return kExitUsage;
      index = *i;
      break;
    }
    if (index < 0) {
      std::cerr << MessagePrefix()
                << "no --index and no scheduler array index in the "
                   "environment\n";
      return kExitUsage;
    }
  }
  const int64_t chunk = args->Has("--chunk") ? args->Whole("--chunk") : 1;
  StatusOr<std::vector<sweep::TaskOutcome>> outcomes = sweep::RunTasks(
      target, static_cast<int>(index * chunk), static_cast<int>(chunk), ThisProgram());
  if (!outcomes.ok()) return Fail(outcomes.status());
  bool all_ok = true;
  for (const sweep::TaskOutcome& o : *outcomes) {
    std::cout << "task " << o.index << ": " << o.status
              << (o.error.empty() ? "" : " (" + o.error + ")") << "\n";
    all_ok = all_ok && o.status == "ok";
  }
  return all_ok ? kExitOk : kExitError;
}

int SweepSubmitCommand(const Arguments& parsed) {
  const Arguments* args = &parsed;
  const std::string& target = args->positional[0];
  const bool slurm = args->values.count("--slurm") > 0;
  const bool dry_run = args->values.count("--dry-run") > 0;
  if (!slurm) {
    std::cerr << MessagePrefix()
              << "only --slurm is supported (see configs/README.md for a "
                 "GNU parallel recipe)\n";
    return kExitUsage;
  }
  sweep::SlurmOptions options;
  options.program = ThisProgram();
  options.partition = args->Value("--partition");
  options.time = args->Value("--time");
  options.mem = args->Value("--mem");
  if (args->all.count("--sbatch-arg")) options.sbatch_args = args->all.at("--sbatch-arg");
  if (args->Has("--max-parallel")) {
    options.max_parallel = static_cast<int>(args->Whole("--max-parallel"));
  }
  if (args->Has("--chunk")) options.chunk = static_cast<int>(args->Whole("--chunk"));
  StatusOr<sweep::SlurmJobs> jobs = sweep::WriteSlurmScripts(target, options);
  if (!jobs.ok()) return Fail(jobs.status());
  if (dry_run) {
    for (const std::string& script : {jobs->array_script, jobs->collect_script}) {
      std::ifstream in(script);
      std::cout << "# " << script << "\n" << in.rdbuf() << "\n";
    }
    return kExitOk;
  }
  Status submitted = sweep::SubmitSlurm(&*jobs);
  if (!submitted.ok()) return Fail(submitted);
  std::cout << "array job " << jobs->array_job << " (--array=" << jobs->array_spec
            << "), collect job " << jobs->collect_job << "\n";
  return kExitOk;
}

int SweepCollectCommand(const Arguments& parsed) {
  const Arguments* args = &parsed;
  const std::string& target = args->positional[0];
  StatusOr<sweep::CollectReport> report = sweep::Collect(target);
  if (!report.ok()) return Fail(report.status());
  if (Status drawn = DrawSweepPlots(target, *report, *args); !drawn.ok()) return Fail(drawn);
  std::cout << report->ok << " ok, " << report->failed << " failed, " << report->pending
            << " pending";
  if (report->eliminated > 0) std::cout << ", " << report->eliminated << " eliminated";
  if (report->best_point) {
    std::cout << "; best point " << *report->best_point << " (objective " << report->best_objective
              << "), written to " << target << "/best.toml";
  }
  std::cout << "\n";
  // A sweep that ranked nothing has failed, whatever ran: say why.
  if (!report->best_point) {
    std::cerr << MessagePrefix() << "no point could be ranked: ";
    if (report->ok_without_objective > 0) {
      std::cerr << report->ok_without_objective
                << " run(s) succeeded but their summaries have no value for the objective"
                   " (a misspelt metric?); see results.csv\n";
    } else if (report->pending > 0) {
      std::cerr << "no point has all its runs done yet (" << report->pending
                << " pending); run the sweep first\n";
    } else {
      std::cerr << "every point has a failed run; see results.csv and the runs' stderr.txt\n";
    }
    return kExitError;
  }
  return kExitOk;
}

}  // namespace ratslam::apps
