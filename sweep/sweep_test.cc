#include "sweep/sweep.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "common/output_guard.h"
#include "common/scratch_dir.h"
#include "dataset/dataset.h"
#include "io/config.h"
#include "io/run_outputs.h"
#include "sweep/sweep_internal.h"
#include "tests/test_paths.h"

extern char** environ;

namespace ratslam::sweep {
namespace {
namespace fs = std::filesystem;

const ScratchDir& Scratch() {
  static const ScratchDir dir("ratslam_sweep_test");
  return dir;
}

std::string Write(const std::string& name, const std::string& text) {
  const fs::path path = Scratch().path() / name;
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
  return path.string();
}

// A 40 m square walked twice at 1 m/s, with four access points heard by distance and ground
// truth: a Wi-Fi-only replay of it takes milliseconds.
std::string SquareWalk(const std::string& name, double noise_dbm) {
  dataset::Dataset d;
  d.name = name;
  const double side = 10.0;
  double x = 0.0, y = 0.0, heading = 0.0;
  const double aps[4][2] = {{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  for (int t = 0; t <= 80; ++t) {
    const bool corner = t > 0 && t % 10 == 0;
    d.odometry.push_back({static_cast<double>(t), 1.0, corner ? M_PI / 2 : 0.0});
    d.ground_truth.push_back({static_cast<double>(t), x, y, heading, 0});
    if (t % 2 == 0) {
      WifiScan scan;
      scan.time_s = t + 0.5;
      for (int a = 0; a < 4; ++a) {
        const double dist = std::hypot(x - aps[a][0], y - aps[a][1]) + 1.0;
        const double wobble = noise_dbm * std::sin(7.0 * t + a);
        scan.readings.push_back(
            {"ap" + std::to_string(a), -40.0 - 20.0 * std::log10(dist) + wobble});
      }
      d.wifi.push_back(scan);
    }
    x += std::cos(heading);
    y += std::sin(heading);
    if (corner) heading += M_PI / 2;
    (void)side;
  }
  const std::string folder = (Scratch().path() / "data" / name).string();
  EXPECT_TRUE(dataset::WriteDataset(d, folder).ok());
  return folder;
}

const char kBase[] = R"([front_end]
kind = "fused"
[fused]
use_camera = false
use_wifi = true
use_compass = false
recency_s = 10.0
[pose_cells]
cell_size_m = 1.0
)";

std::string SweepFile(const std::string& name, const std::string& body) {
  Write("base.toml", kBase);
  return Write(name,
               "[sweep]\nbase_config = \"base.toml\"\nobjective = \"map_ate_m\"\n"
               "metrics = [\"templates\", \"match_rate_within_m.5\"]\n" +
                   body);
}

TEST(SweepPlanTest, GridExpandsEveryCombinationInAStableOrder) {
  SquareWalk("a", 0.0);
  SquareWalk("b", 1.0);
  const std::string path = SweepFile("grid.toml", R"(
[[datasets]]
glob = "data/*"
[parameters]
"wifi.match_threshold" = {linear = [0.2, 0.6, 3]}
"fused.recency_templates" = [0, 5]
)");
  StatusOr<SweepSpec> spec = LoadSweepFile(path);
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  ASSERT_EQ(spec->datasets.size(), 2u);  // the glob: one data set per match, sorted
  EXPECT_EQ(fs::path(spec->datasets[0][0]).filename(), "a");
  StatusOr<Plan> plan = MakePlan(*spec);
  ASSERT_TRUE(plan.ok()) << plan.status().message();
  EXPECT_EQ(plan->points, 6);
  ASSERT_EQ(plan->tasks.size(), 12u);
  // Parameters in key order (fused before wifi); point-major, data sets inside.
  EXPECT_EQ(plan->tasks[0].overrides,
            (std::vector<std::pair<std::string, std::string>>{{"fused.recency_templates", "0"},
                                                              {"wifi.match_threshold", "0.2"}}));
  EXPECT_EQ(plan->tasks[1].dataset, 1);
  EXPECT_EQ(plan->tasks[1].point, 0);
  EXPECT_EQ(plan->tasks[3].overrides[1].second, "0.4");
  EXPECT_EQ(plan->tasks[11].overrides,
            (std::vector<std::pair<std::string, std::string>>{{"fused.recency_templates", "5"},
                                                              {"wifi.match_threshold", "0.6"}}));
  StatusOr<fusion::PipelineOptions> config = TaskConfig(*plan, plan->tasks[11]);
  ASSERT_TRUE(config.ok());
  EXPECT_EQ(config->sensors.fused.recency_templates, 5);
  EXPECT_EQ(config->sensors.wifi.match_threshold, 0.6);
  EXPECT_EQ(config->sensors.fused.recency_s, 10.0);  // from the base configuration
  // Re-planning into the same folder is allowed and changes nothing; another plan is refused.
  const std::string dir = (Scratch().path() / "plan-grid").string();
  ASSERT_TRUE(WritePlan(*plan, dir).ok());
  ASSERT_TRUE(WritePlan(*MakePlan(*LoadSweepFile(path)), dir).ok());
  StatusOr<Plan> read = ReadPlan(dir);
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(read->tasks.size(), 12u);
  EXPECT_EQ(read->tasks[7].overrides, plan->tasks[7].overrides);
  Plan other = *plan;
  other.tasks.pop_back();
  EXPECT_FALSE(WritePlan(other, dir).ok());
}

TEST(SweepPlanTest, RangesAndSeededRandomDraws) {
  SquareWalk("a", 0.0);
  const std::string grid = SweepFile("ranges.toml", R"(
[[datasets]]
data = ["data/a"]
[parameters]
"wifi.kernel_variance_dbm2" = {log = [1, 100, 3]}
"local_view.skip_recent_templates" = {linear = [0, 5, 4]}
)");
  StatusOr<Plan> plan = MakePlan(*LoadSweepFile(grid));
  ASSERT_TRUE(plan.ok()) << plan.status().message();
  // Integer ends give integers: log 1, 10, 100; linear 0, 5/3, 10/3, 5 rounded to 0, 2, 3, 5.
  EXPECT_EQ(plan->spec.parameters[0].values, (std::vector<std::string>{"0", "2", "3", "5"}));
  EXPECT_EQ(plan->spec.parameters[1].values, (std::vector<std::string>{"1", "10", "100"}));
  EXPECT_EQ(plan->points, 12);

  auto random_plan = [&](int seed) {
    const std::string path = SweepFile(
        "random.toml", "method = \"random\"\nsamples = 20\nseed = " + std::to_string(seed) + R"(
[[datasets]]
data = ["data/a"]
[parameters]
"wifi.match_threshold" = {uniform = [0.1, 0.5]}
"fused.recency_s" = {log_uniform = [1, 100]}
"fused.recency_templates" = [0, 3]
)");
    return MakePlan(*LoadSweepFile(path));
  };
  StatusOr<Plan> a = random_plan(7), b = random_plan(7), c = random_plan(8);
  ASSERT_TRUE(a.ok()) << a.status().message();
  ASSERT_EQ(a->tasks.size(), 20u);
  std::set<std::string> distinct;
  for (size_t i = 0; i < a->tasks.size(); ++i) {
    EXPECT_EQ(a->tasks[i].overrides, b->tasks[i].overrides);  // same seed, same draws
    const double threshold = std::stod(a->tasks[i].overrides[2].second);
    const double recency = std::stod(a->tasks[i].overrides[0].second);
    EXPECT_GE(threshold, 0.1);
    EXPECT_LE(threshold, 0.5);
    EXPECT_GE(recency, 1.0);
    EXPECT_LE(recency, 100.0);
    distinct.insert(a->tasks[i].overrides[2].second);
  }
  EXPECT_EQ(distinct.size(), 20u);
  EXPECT_NE(a->tasks[0].overrides, c->tasks[0].overrides);  // another seed, other draws
}

TEST(SweepPlanTest, BadKeysAndValuesNameTheSweepFileLine) {
  SquareWalk("a", 0.0);
  auto error = [&](const std::string& parameters) {
    const std::string path =
        SweepFile("bad.toml", "[[datasets]]\ndata = [\"data/a\"]\n[parameters]\n" + parameters);
    StatusOr<SweepSpec> spec = LoadSweepFile(path);
    if (!spec.ok()) return spec.status().message();
    StatusOr<Plan> plan = MakePlan(*spec);
    return plan.ok() ? std::string() : plan.status().message();
  };
  const std::string prefix = (Scratch().path() / "bad.toml").string() + ":";
  // Lines: 1-4 [sweep], 5-6 [[datasets]], 7 [parameters], 8 the first parameter.
  EXPECT_EQ(error("\"wifi.match_treshold\" = [0.2]\n"),
            prefix +
                "8: parameter 'wifi.match_treshold' = 0.2: unknown key 'match_treshold' in "
                "[wifi] (did you mean 'match_threshold'?)");
  EXPECT_EQ(error("\"fused.recency_s\" = [1.0]\n\"wifi.match_threshold\" = [0.5, 1.5]\n"),
            prefix +
                "9: parameter 'wifi.match_threshold' = 1.5: wifi.match_threshold: must be in "
                "[0, 1]");
  EXPECT_EQ(error("\"pose_cells.dim_xy_cells\" = [2.5]\n"),
            prefix +
                "8: parameter 'pose_cells.dim_xy_cells' = 2.5: pose_cells.dim_xy_cells: "
                "expected an integer");
  EXPECT_NE(
      error("\"wifi.match_threshold\" = {uniform = [0.1, 0.2]}\n").find("method = \"random\""),
      std::string::npos);
  // Each value alone is valid; a relation between two swept keys fails in one combination.
  const std::string relation =
      error("\"pdr.smoothing_s\" = [0.1, 1.5]\n\"pdr.baseline_s\" = [1.0, 3.0]\n");
  EXPECT_NE(relation.find(": point 1 (pdr.baseline_s = 1.0, pdr.smoothing_s = 1.5): "
                          "pdr.baseline_s: must exceed smoothing_s"),
            std::string::npos)
      << relation;
}

// A data path the system refuses to look up (a path longer than PATH_MAX, a file used as a
// folder) is a missing data set, not an exception (found by sweep_file_fuzzer).
TEST(SweepPlanTest, DataPathsTheSystemCannotLookUpAreMissingDataSets) {
  Write("plain_file", "not a folder\n");
  const std::string prefix = (Scratch().path() / "bad.toml").string() + ":";
  for (const std::string& data : {"data/" + std::string(5000, 'x'), std::string("plain_file/a")}) {
    const std::string path = SweepFile("bad.toml", "[[datasets]]\ndata = [\"" + data +
                                                       "\"]\n[parameters]\n\"fused.recency_s\" = "
                                                       "[1.0]\n");
    StatusOr<SweepSpec> spec = LoadSweepFile(path);
    ASSERT_FALSE(spec.ok()) << data;
    EXPECT_EQ(spec.status().message().rfind(prefix, 0), 0u) << spec.status().message();
    EXPECT_NE(spec.status().message().find("no such data set"), std::string::npos)
        << spec.status().message();
  }
}

// A fake worker: crashes for data set "crash", hangs for "hang", and runs the real program
// otherwise; every start is appended to a log so that repeats can be counted.
std::string FakeProgram(const std::string& log) {
  const std::string path =
      Write("fake_ratslam.sh", "#!/bin/sh\necho \"$*\" >> " + log +
                                   "\ncase \"$*\" in\n"
                                   "  */crash\\ *) kill -SEGV $$ ;;\n"
                                   "  */hang\\ *) sleep 60 ;;\n"
                                   "esac\nexec " +
                                   ratslam::test_paths::RatslamBinary() + " \"$@\"\n");
  fs::permissions(path, fs::perms::owner_all);
  return path;
}

int Starts(const std::string& log, const std::string& run_folder) {
  std::ifstream in(log);
  std::string line;
  int n = 0;
  while (std::getline(in, line)) n += line.find("--out " + run_folder) != std::string::npos;
  return n;
}

TEST(SweepRunTest, FailuresAreRecordedWhileTheOthersFinishAndCollectRanksPoints) {
  SquareWalk("a", 0.0);
  SquareWalk("b", 1.5);
  fs::create_directories(Scratch().path() / "broken" / "crash");
  fs::create_directories(Scratch().path() / "broken" / "hang");
  fs::create_directories(Scratch().path() / "broken" / "nomanifest");
  const std::string path = SweepFile("run.toml", R"(timeout_s = 10
[[datasets]]
data = ["data/a"]
[[datasets]]
data = ["data/b"]
[parameters]
"wifi.match_threshold" = [0.3, 0.99]
)");
  StatusOr<Plan> plan = MakePlan(*LoadSweepFile(path));
  ASSERT_TRUE(plan.ok()) << plan.status().message();
  // Three broken tasks beside the four good ones.
  for (const char* broken : {"crash", "hang", "nomanifest"}) {
    plan->spec.datasets.push_back({(Scratch().path() / "broken" / broken).string()});
    Task t;
    t.index = static_cast<int>(plan->tasks.size());
    t.point = 0;
    t.dataset = static_cast<int>(plan->spec.datasets.size()) - 1;
    t.overrides = plan->tasks[0].overrides;
    plan->tasks.push_back(t);
  }
  const std::string dir = (Scratch().path() / "sweep-run").string();
  ASSERT_TRUE(WritePlan(*plan, dir).ok());
  const std::string log = (Scratch().path() / "starts.log").string();
  RunOptions options;
  options.program = FakeProgram(log);
  options.jobs = 3;
  StatusOr<RunReport> report = RunSweep(dir, options);
  ASSERT_TRUE(report.ok()) << report.status().message();
  EXPECT_EQ(report->done, 7);
  EXPECT_EQ(report->failed, 3);
  StatusOr<std::vector<TaskOutcome>> outcomes = ReadOutcomes(dir);
  ASSERT_TRUE(outcomes.ok());
  for (int i = 0; i < 4; ++i) EXPECT_EQ((*outcomes)[i].status, "ok") << (*outcomes)[i].error;
  EXPECT_EQ((*outcomes)[4].status, "failed");
  EXPECT_EQ((*outcomes)[4].exit_code, 128 + SIGSEGV);
  EXPECT_EQ((*outcomes)[5].status, "timeout");
  EXPECT_LT((*outcomes)[5].wall_s, 30.0);
  EXPECT_EQ((*outcomes)[6].status, "failed");
  EXPECT_NE((*outcomes)[6].error.find("manifest"), std::string::npos) << (*outcomes)[6].error;
  // Small run folders: the summary, config and trajectory stay, the rest is gone.
  const fs::path run0 = fs::path(dir) / "runs" / "00000";
  EXPECT_TRUE(fs::exists(run0 / "summary.json"));
  EXPECT_TRUE(fs::exists(run0 / "trajectory_tum.txt"));
  EXPECT_FALSE(fs::exists(run0 / "frames.csv"));

  // Running again repeats nothing.
  StatusOr<RunReport> again = RunSweep(dir, options);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->done, 0);
  EXPECT_EQ(again->skipped, 7);
  EXPECT_EQ(Starts(log, (fs::path(dir) / "runs").string()), 7);

  StatusOr<CollectReport> collected = Collect(dir);
  ASSERT_TRUE(collected.ok()) << collected.status().message();
  EXPECT_EQ(collected->ok, 4);
  EXPECT_EQ(collected->failed, 3);
  // Point 0 has failed runs, so it is not ranked: point 1 is the best.
  ASSERT_TRUE(collected->best_point.has_value());
  EXPECT_EQ(*collected->best_point, 1);
  // The objective is the mean of point 1's two runs, read independently from their summaries.
  double sum = 0.0;
  for (int i : {2, 3}) {
    std::ifstream in(fs::path(dir) / "runs" / ("0000" + std::to_string(i)) / "summary.json");
    sum += nlohmann::json::parse(in).at("map_ate_m").get<double>();
  }
  EXPECT_DOUBLE_EQ(collected->best_objective, sum / 2);
  StatusOr<fusion::PipelineOptions> best =
      io::LoadConfigFile((fs::path(dir) / "best.toml").string());
  ASSERT_TRUE(best.ok()) << best.status().message();
  EXPECT_EQ(best->sensors.wifi.match_threshold, 0.99);
  EXPECT_EQ(best->sensors.fused.recency_s, 10.0);
  std::ifstream csv(fs::path(dir) / "results.csv");
  std::string header, line;
  std::getline(csv, header);
  EXPECT_EQ(header,
            "index,point,dataset,data,status,exit_code,wall_s,wifi.match_threshold,map_ate_m,"
            "templates,match_rate_within_m.5,error");
  int rows = 0;
  while (std::getline(csv, line)) {
    ++rows;
    // Each row names its data set by its path too (the fourth field: the paths are absolute).
    size_t at = 0;
    for (int field = 0; field < 3; ++field) at = line.find(',', at) + 1;
    EXPECT_EQ(line.substr(at, 1), "/") << line;
  }
  EXPECT_EQ(rows, 7);
}

TEST(SweepRunTest, AStoppedSweepResumesWithoutRepeatingOrLosingRuns) {
  SquareWalk("a", 0.0);
  const std::string path = SweepFile("resume.toml", R"(
[[datasets]]
data = ["data/a"]
[parameters]
"wifi.match_threshold" = {linear = [0.1, 0.9, 9]}
)");
  StatusOr<Plan> plan = MakePlan(*LoadSweepFile(path));
  ASSERT_TRUE(plan.ok());
  const std::string dir = (Scratch().path() / "sweep-resume").string();
  ASSERT_TRUE(WritePlan(*plan, dir).ok());
  const std::string log = (Scratch().path() / "resume.log").string();
  // Stop once three runs have ended (as Ctrl-C would): running ones end unrecorded.
  std::atomic<bool> stop{false};
  struct StopAfter : ProgressSink {
    std::atomic<bool>* stop;
    void Update(const ProgressUpdate& u) override {
      if (u.done >= 3) stop->store(true);
    }
  } stopper;
  stopper.stop = &stop;
  RunOptions options;
  options.program = FakeProgram(log);
  options.jobs = 2;
  options.progress = &stopper;
  options.stop_requested = &stop;
  StatusOr<RunReport> first = RunSweep(dir, options);
  ASSERT_TRUE(first.ok());
  EXPECT_GE(first->done, 3);
  EXPECT_LT(first->done, 9);
  EXPECT_GT(first->pending, 0);
  std::set<int> ended;
  const StatusOr<std::vector<TaskOutcome>> after_stop = ReadOutcomes(dir);
  ASSERT_TRUE(after_stop.ok());
  for (const TaskOutcome& o : *after_stop) {
    if (o.status != "pending") ended.insert(o.index);
  }
  options.progress = nullptr;
  stop.store(false);
  std::ofstream(log, std::ios::trunc).close();
  StatusOr<RunReport> second = RunSweep(dir, options);
  ASSERT_TRUE(second.ok());
  EXPECT_EQ(second->skipped, static_cast<int>(ended.size()));
  EXPECT_EQ(second->done + second->skipped, 9);
  const StatusOr<std::vector<TaskOutcome>> at_end = ReadOutcomes(dir);
  ASSERT_TRUE(at_end.ok());
  for (const TaskOutcome& o : *at_end) EXPECT_EQ(o.status, "ok") << o.index << ": " << o.error;
  // No run that had ended was started again; each pending one exactly once.
  char name[16];
  for (int i = 0; i < 9; ++i) {
    std::snprintf(name, sizeof name, "%05d", i);
    EXPECT_EQ(Starts(log, (fs::path(dir) / "runs" / name).string() + " "), ended.count(i) ? 0 : 1)
        << i;
  }
}

TEST(SweepRunTest, OneTaskByIndexAsAnArrayJobRunsIt) {
  SquareWalk("a", 0.0);
  const std::string path = SweepFile("task.toml", R"(
[[datasets]]
data = ["data/a"]
[parameters]
"wifi.match_threshold" = [0.2, 0.4]
)");
  const std::string dir = (Scratch().path() / "sweep-task").string();
  ASSERT_TRUE(WritePlan(*MakePlan(*LoadSweepFile(path)), dir).ok());
  StatusOr<TaskOutcome> one = RunTask(dir, 1, ratslam::test_paths::RatslamBinary());
  ASSERT_TRUE(one.ok()) << one.status().message();
  EXPECT_EQ(one->status, "ok");
  EXPECT_FALSE(RunTask(dir, 2, ratslam::test_paths::RatslamBinary()).ok());  // no such task
  StatusOr<std::vector<TaskOutcome>> outcomes = ReadOutcomes(dir);
  EXPECT_EQ((*outcomes)[0].status, "pending");
  EXPECT_EQ((*outcomes)[1].status, "ok");
}

// The Slurm scripts cover only what is pending, in ranges, with the parallel limit.
TEST(SweepSlurmTest, ArrayCoversPendingTasksInRanges) {
  SquareWalk("a", 0.0);
  const std::string path = SweepFile("slurm.toml", R"(
[[datasets]]
data = ["data/a"]
[parameters]
"wifi.match_threshold" = [0.1, 0.2, 0.3, 0.4, 0.5]
)");
  const std::string dir = (Scratch().path() / "sweep-slurm").string();
  ASSERT_TRUE(WritePlan(*MakePlan(*LoadSweepFile(path)), dir).ok());
  ASSERT_TRUE(
      RunTasks(dir, 1, 2, ratslam::test_paths::RatslamBinary()).ok());  // tasks 1 and 2 done
  SlurmOptions options;
  options.program = "/opt/it's here/ratslam";
  options.max_parallel = 2;
  options.time = "00:10:00";
  options.sbatch_args = {"--account=lab"};
  StatusOr<SlurmJobs> jobs = WriteSlurmScripts(dir, options);
  ASSERT_TRUE(jobs.ok()) << jobs.status().message();
  EXPECT_EQ(jobs->array_spec, "0,3-4%2");
  std::ifstream in(jobs->array_script);
  const std::string script((std::istreambuf_iterator<char>(in)), {});
  EXPECT_NE(script.find("#SBATCH --array=0,3-4%2\n"), std::string::npos) << script;
  EXPECT_NE(script.find("#SBATCH --time=00:10:00\n#SBATCH --account=lab\n"), std::string::npos);
  EXPECT_NE(script.find("exec '/opt/it'\\''s here/ratslam' sweep task '"), std::string::npos)
      << script;
  options.chunk = 2;  // elements 0 (tasks 0-1), 1 (2-3), 2 (4): 1 and 2 hold pending tasks too
  jobs = WriteSlurmScripts(dir, options);
  ASSERT_TRUE(jobs.ok());
  EXPECT_EQ(jobs->array_spec, "0-2%2");
  ASSERT_TRUE(RunTasks(dir, 0, 5, ratslam::test_paths::RatslamBinary()).ok());
  EXPECT_FALSE(WriteSlurmScripts(dir, options).ok());  // nothing pending
}

// Successive halving on a synthetic objective with a known optimum: the fake worker scores
// (match_threshold - 0.37)^2 plus a per-data-set offset, so point 10 (threshold 10/27) is best.
TEST(SweepHalvingTest, FindsTheKnownOptimumWithAThirdOfTheGridsRuns) {
  std::string data;
  for (int d = 0; d < 9; ++d) {
    const std::string name = std::string(1, 'd') + std::to_string(d);
    fs::create_directories(Scratch().path() / "halving" / name);
    data += "[[datasets]]\ndata = [\"halving/d";
    data += std::to_string(d);
    data += "\"]\n";
  }
  const std::string worker = Write("fake_objective.sh", R"(#!/bin/sh
while [ $# -gt 0 ]; do
  case "$1" in
    --config) config=$2; shift ;;
    --data) data=$2; shift ;;
    --out) out=$2; shift ;;
  esac
  shift
done
x=$(awk -F' = ' '/^\[/ {s=$0} s=="[wifi]" && $1=="match_threshold" {print $2}' "$config")
d=${data##*/d}
awk -v x="$x" -v d="$d" 'BEGIN { printf "{\"map_ate_m\": %.12f}\n", (x-0.37)^2 + 0.01*d + 0.0001*((d*7)%3)*x }' > "$out/summary.json"
)");
  fs::permissions(worker, fs::perms::owner_all);
  const std::string path =
      SweepFile("halving.toml", "search = \"halving\"\nhalving_rate = 3\n" + data +
                                    "[parameters]\n\"wifi.match_threshold\" = "
                                    "{linear = [0.0, 1.0, 28]}\n");
  const std::string dir = (Scratch().path() / "sweep-halving").string();
  StatusOr<Plan> plan = MakePlan(*LoadSweepFile(path));
  ASSERT_TRUE(plan.ok()) << plan.status().message();
  ASSERT_EQ(plan->tasks.size(), 28u * 9u);
  ASSERT_TRUE(WritePlan(*plan, dir).ok());
  RunOptions options;
  options.program = worker;
  options.jobs = 2;
  StatusOr<RunReport> report = RunSweep(dir, options);
  ASSERT_TRUE(report.ok()) << report.status().message();
  // 28 points on 1 data set, the best 10 on 3, the best 4 on all 9: 28 + 20 + 24 runs.
  EXPECT_EQ(report->done, 72);
  EXPECT_LE(report->done * 3, static_cast<int>(plan->tasks.size()));
  StatusOr<CollectReport> collected = Collect(dir);
  ASSERT_TRUE(collected.ok()) << collected.status().message();
  EXPECT_EQ(collected->ok, 72);
  EXPECT_EQ(collected->eliminated, 28 * 9 - 72);
  // results.json counts them, and names each such run.
  std::ifstream results(fs::path(dir) / "results.json");
  const nlohmann::json j = nlohmann::json::parse(results);
  EXPECT_EQ(j.at("eliminated").get<int>(), 28 * 9 - 72);
  int named = 0;
  for (const nlohmann::json& run : j.at("runs")) named += run.at("status") == "eliminated";
  EXPECT_EQ(named, 28 * 9 - 72);
  ASSERT_TRUE(collected->best_point.has_value());
  EXPECT_EQ(*collected->best_point, 10);
  // Resuming a finished halving runs nothing.
  StatusOr<RunReport> again = RunSweep(dir, options);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->done, 0);
}

// The shipped sweep files plan (every value valid for the configuration they vary).
TEST(SweepPlanTest, ShippedSweepFilesPlan) {
  const fs::path data = fs::path(ratslam::test_paths::SharedDataDir()) / "ipin2023-t3";
  if (!fs::exists(data)) GTEST_SKIP() << "missing " << data;
  const fs::path sweeps = fs::path(ratslam::test_paths::SourceDir()) / "configs" / "sweeps";
  const std::map<std::string, size_t> expected = {{"ipin2023-wifi-compass.toml", 2160},
                                                  {"ipin2023-wifi-compass-halving.toml", 2160},
                                                  {"ipin2023-wifi-compass-holdout.toml", 11}};
  for (const auto& [name, tasks] : expected) {
    StatusOr<SweepSpec> spec = LoadSweepFile((sweeps / name).string());
    ASSERT_TRUE(spec.ok()) << spec.status().message();
    StatusOr<Plan> plan = MakePlan(*spec);
    ASSERT_TRUE(plan.ok()) << plan.status().message();
    EXPECT_EQ(plan->tasks.size(), tasks) << name;
  }
}

// command = "evaluate" runs the FABMAP benchmark per task and reads evaluation.json.
TEST(SweepRunTest, EvaluateSweepsReadTheBenchmarksMetrics) {
  const fs::path site = fs::path(ratslam::test_paths::SharedDataDir()) / "msft-ilc20-site1";
  if (!fs::exists(site)) GTEST_SKIP() << "missing " << site;
  const std::string path = Write(
      "evaluate.toml", "[sweep]\ncommand = \"evaluate\"\nbase_config = \"" +
                           std::string(ratslam::test_paths::SourceDir()) +
                           "/configs/msft-ilc20-wifi.toml\"\n"
                           "objective = \"correct_within_m.5\"\n"
                           "goal = \"maximize\"\n[[datasets]]\ndata = [\"" +
                           site.string() + "\"]\n[parameters]\n\"wifi_words.bins\" = [1, 8]\n");
  const std::string dir = (Scratch().path() / "sweep-evaluate").string();
  StatusOr<Plan> plan = MakePlan(*LoadSweepFile(path));
  ASSERT_TRUE(plan.ok()) << plan.status().message();
  ASSERT_TRUE(WritePlan(*plan, dir).ok());
  RunOptions options;
  options.program = ratslam::test_paths::RatslamBinary();
  options.jobs = 2;
  StatusOr<RunReport> report = RunSweep(dir, options);
  ASSERT_TRUE(report.ok()) << report.status().message();
  StatusOr<CollectReport> collected = Collect(dir);
  ASSERT_TRUE(collected.ok());
  ASSERT_EQ(collected->ok, 2);
  ASSERT_EQ(collected->points.size(), 2u);
  for (const PointSummary& p : collected->points) {
    ASSERT_TRUE(p.objective.has_value());
    EXPECT_GT(*p.objective, 0.0);
    EXPECT_LE(*p.objective, 1.0);
  }
  EXPECT_TRUE(fs::exists(fs::path(dir) / "runs" / "00000" / "evaluation.json"));
}

// A runner killed between starting a run and writing its `pid` file leaves a run that no file
// names (CI once caught the kill in that window: the orphan's outputs landed in the next
// attempt's folder, which refused to overwrite them). The resumed sweep must still end it: here
// an orphan that has the run folder among its arguments, in its own process group, and no pid
// file.
TEST(SweepRunTest, AnOrphanWithoutAPidFileIsEndedBeforeItsFolderIsReused) {
  SquareWalk("a", 0.0);
  const std::string path = SweepFile("orphan.toml", R"(
[[datasets]]
data = ["data/a"]
[parameters]
"wifi.match_threshold" = [0.3]
)");
  const std::string dir = (Scratch().path() / "sweep-orphan").string();
  ASSERT_TRUE(WritePlan(*MakePlan(*LoadSweepFile(path)), dir).ok());
  const std::string folder = (fs::path(dir) / "runs" / "00000").string();
  fs::create_directories(folder);
  ASSERT_FALSE(fs::exists(folder + "/pid"));
  std::string shell = "/bin/sh", c = "-c", loop = "while :; do sleep 1; done", arg0 = folder;
  char* argv[] = {shell.data(), c.data(), loop.data(), arg0.data(), nullptr};
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attributes, 0);
  pid_t orphan = -1;
  ASSERT_EQ(posix_spawn(&orphan, shell.c_str(), nullptr, &attributes, argv, environ), 0);
  posix_spawnattr_destroy(&attributes);
  struct EndAnyway {  // a failing check must not leave the loop running (it would hold ctest's
    pid_t pid;        // output open)
    ~EndAnyway() {
      kill(-pid, SIGKILL);
      waitpid(pid, nullptr, WNOHANG);
    }
  } end_anyway{orphan};
  usleep(100000);  // let it start
  int status = 0;
  ASSERT_EQ(waitpid(orphan, &status, WNOHANG), 0) << "the orphan ended by itself";
  RunOptions options;
  options.program = FakeProgram((Scratch().path() / "orphan.log").string());
  StatusOr<RunReport> report = RunSweep(dir, options);
  ASSERT_TRUE(report.ok()) << report.status().message();
  EXPECT_EQ(report->done, 1);
  ASSERT_EQ(waitpid(orphan, &status, WNOHANG), orphan) << "the orphan still runs";
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
  const StatusOr<std::vector<TaskOutcome>> outcomes = ReadOutcomes(dir);
  ASSERT_TRUE(outcomes.ok());
  EXPECT_EQ((*outcomes)[0].status, "ok") << (*outcomes)[0].error;
}

// The runner itself killed (SIGKILL, no chance to clean up) half-way: the same command resumes,
// repeats no run that had ended, and ends any run the dead runner left behind.
TEST(SweepRunTest, AKilledRunnerResumesWithoutRepeatingOrLosingRuns) {
  SquareWalk("a", 0.0);
  const std::string path = SweepFile("kill.toml", R"(
[[datasets]]
data = ["data/a"]
[parameters]
"wifi.match_threshold" = {linear = [0.1, 0.9, 12]}
)");
  const std::string dir = (Scratch().path() / "sweep-kill").string();
  ASSERT_TRUE(WritePlan(*MakePlan(*LoadSweepFile(path)), dir).ok());
  std::string program = ratslam::test_paths::RatslamBinary(), run = "run", folder = dir,
              jobs = "--jobs", two = "2", quiet = "--quiet", sweep = "sweep";
  char* argv[] = {program.data(), sweep.data(), run.data(),   folder.data(),
                  jobs.data(),    two.data(),   quiet.data(), nullptr};
  pid_t runner = -1;
  ASSERT_EQ(posix_spawn(&runner, program.c_str(), nullptr, nullptr, argv, environ), 0);
  auto ended = [&] {
    std::set<int> out;
    StatusOr<std::vector<TaskOutcome>> outcomes = ReadOutcomes(dir);
    for (const TaskOutcome& o : *outcomes) {
      if (o.status != "pending") out.insert(o.index);
    }
    return out;
  };
  for (int i = 0; i < 3000 && ended().size() < 4; ++i) usleep(10000);
  kill(runner, SIGKILL);
  int status = 0;
  waitpid(runner, &status, 0);
  const std::set<int> before = ended();
  ASSERT_GE(before.size(), 4u);
  ASSERT_LT(before.size(), 12u) << "the sweep finished before it could be killed";
  const std::string log = (Scratch().path() / "kill.log").string();
  RunOptions options;
  options.program = FakeProgram(log);
  options.jobs = 2;
  // A run the killed runner was starting may still hold its copy of the folder's lock until its
  // exec closes it (seen once under load): the lock is free within moments.
  for (int i = 0; i < 500 && !FolderLock::Acquire(dir, "test").ok(); ++i) usleep(10000);
  StatusOr<RunReport> resumed = RunSweep(dir, options);
  ASSERT_TRUE(resumed.ok()) << resumed.status().message();
  EXPECT_EQ(resumed->skipped, static_cast<int>(before.size()));
  EXPECT_EQ(resumed->done, 12 - static_cast<int>(before.size()));
  char name[16];
  for (int i = 0; i < 12; ++i) {
    std::snprintf(name, sizeof name, "%05d", i);
    EXPECT_EQ(Starts(log, (fs::path(dir) / "runs" / name).string() + " "), before.count(i) ? 0 : 1)
        << i;
  }
  const StatusOr<std::vector<TaskOutcome>> at_end = ReadOutcomes(dir);
  for (const TaskOutcome& o : *at_end) EXPECT_EQ(o.status, "ok") << o.index << ": " << o.error;
}

// An objective may be an expression of metrics; each run's value is computed from its summary.
// A metric is a number at a dotted path; summary.json's flags (finished, fabmap_calibrated) are
// metrics too, as 1 and 0, so that a point's mean over its data sets is the share where it held.
TEST(SweepCollectTest, MetricsAreNumbersOrFlagsAtDottedPaths) {
  const nlohmann::json summary = nlohmann::json::parse(
      R"({"map_ate_m": 2.5, "finished": true, "fabmap_calibrated": false,
          "match_rate_within_m": {"5": 0.75}, "dataset": "route", "run": {"seed": null}})");
  EXPECT_EQ(Metric(summary, "map_ate_m"), 2.5);
  EXPECT_EQ(Metric(summary, "finished"), 1.0);
  EXPECT_EQ(Metric(summary, "fabmap_calibrated"), 0.0);
  EXPECT_EQ(Metric(summary, "match_rate_within_m.5"), 0.75);
  EXPECT_EQ(Metric(summary, "dataset"), std::nullopt);
  EXPECT_EQ(Metric(summary, "run.seed"), std::nullopt);
  EXPECT_EQ(Metric(summary, "match_rate_within_m.10"), std::nullopt);
  EXPECT_EQ(Metric(summary, "map_ate_m.x"), std::nullopt);
}

TEST(SweepRunTest, ObjectiveExpressionsCombineMetrics) {
  SquareWalk("a", 0.0);
  Write("base.toml", kBase);
  const std::string path = Write("expression.toml", R"([sweep]
base_config = "base.toml"
objective = "(map_ate_m + 0.5 * templates) / 2 - -1"
[[datasets]]
data = ["data/a"]
[parameters]
"wifi.match_threshold" = [0.2, 0.6]
)");
  StatusOr<SweepSpec> spec = LoadSweepFile(path);
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  EXPECT_EQ(spec->metrics, (std::vector<std::string>{"map_ate_m", "templates"}));
  const std::string dir = (Scratch().path() / "sweep-expression").string();
  ASSERT_TRUE(WritePlan(*MakePlan(*spec), dir).ok());
  RunOptions options;
  options.program = ratslam::test_paths::RatslamBinary();
  ASSERT_TRUE(RunSweep(dir, options).ok());
  StatusOr<CollectReport> collected = Collect(dir);
  ASSERT_TRUE(collected.ok());
  for (const PointSummary& p : collected->points) {
    std::ifstream in(fs::path(dir) / "runs" / ("0000" + std::to_string(p.point)) / "summary.json");
    const nlohmann::json summary = nlohmann::json::parse(in);
    const double expected =
        (summary.at("map_ate_m").get<double>() + 0.5 * summary.at("templates").get<double>()) / 2 +
        1;
    ASSERT_TRUE(p.objective.has_value());
    EXPECT_DOUBLE_EQ(*p.objective, expected);
    // Every key a real summary has is one a sweep file may name (SummaryKeys is complete).
    const std::vector<std::string>& keys = io::SummaryKeys();
    for (const auto& [key, value] : summary.items()) {
      EXPECT_NE(std::find(keys.begin(), keys.end(), key), keys.end()) << key;
    }
  }
  // While a runner works in the folder, a second one is refused at once.
  {
    StatusOr<FolderLock> held = FolderLock::Acquire(dir, "the first runner");
    ASSERT_TRUE(held.ok()) << held.status().message();
    StatusOr<RunReport> second = RunSweep(dir, options);
    ASSERT_FALSE(second.ok());
    EXPECT_NE(second.status().message().find("in use by another ratslam run"), std::string::npos)
        << second.status().message();
    EXPECT_NE(second.status().message().find("the first runner"), std::string::npos);
  }
  // A misspelt metric is refused when the sweep is planned, not after every task has run.
  const std::string misspelt = Write("misspelt.toml", R"([sweep]
objective = "map_ate"
[[datasets]]
data = ["data/a"]
)");
  EXPECT_EQ(LoadSweepFile(misspelt).status().message(),
            misspelt +
                ":2: sweep.objective: 'map_ate' is not a key of summary.json (did you "
                "mean 'map_ate_m'?)");
  const std::string misspelt_metric = Write("misspelt-metric.toml", R"([sweep]
objective = "map_ate_m"
metrics = ["templates", "match_rate.5"]
[[datasets]]
data = ["data/a"]
)");
  EXPECT_NE(LoadSweepFile(misspelt_metric)
                .status()
                .message()
                .find("sweep.metrics: 'match_rate.5' is not a key of summary.json"),
            std::string::npos)
      << LoadSweepFile(misspelt_metric).status().message();
  const std::string bad = Write("bad-expression.toml", "[sweep]\nobjective = \"map_ate_m +\"\n");
  EXPECT_EQ(LoadSweepFile(bad).status().message(),
            bad + ":2: sweep.objective: cannot read the objective 'map_ate_m +' near character 12");
}

// A plan.json edited by hand or damaged: every command that reads it refuses it naming the file
// and what is wrong, instead of indexing past its points or converting a fraction to a count;
// collecting a plan whose base configuration no longer reads still writes the results.
TEST(SweepCollectTest, ADamagedPlanIsRefusedNamingItAndCollectKeepsTheResults) {
  SquareWalk("a", 0.0);
  const std::string path = SweepFile("damaged.toml", R"(
[[datasets]]
data = ["data/a"]
[parameters]
"wifi.match_threshold" = [0.3, 0.6]
)");
  StatusOr<Plan> plan = MakePlan(*LoadSweepFile(path));
  ASSERT_TRUE(plan.ok()) << plan.status().message();
  const std::string dir = (Scratch().path() / "sweep-damaged").string();
  ASSERT_TRUE(WritePlan(*plan, dir).ok());
  const std::string plan_path = dir + "/plan.json";
  std::ifstream in(plan_path);
  const nlohmann::json good = nlohmann::json::parse(in);
  auto refusal = [&](const std::function<void(nlohmann::json&)>& damage) {
    nlohmann::json j = good;
    damage(j);
    std::ofstream(plan_path) << j.dump();
    StatusOr<Plan> read = ReadPlan(dir);
    return read.ok() ? std::string("read") : read.status().message();
  };
  EXPECT_EQ(refusal([](nlohmann::json&) {}), "read");
  EXPECT_EQ(refusal([](nlohmann::json& j) { j["points"] = 1.5; }),
            plan_path + ": points must be an integer from 0 to 2");
  EXPECT_EQ(refusal([](nlohmann::json& j) { j["points"] = 2000000000; }),
            plan_path + ": points must be an integer from 0 to 2");
  EXPECT_EQ(refusal([](nlohmann::json& j) { j["points"] = 3; }),
            plan_path + ": points must be an integer from 0 to 2");
  EXPECT_EQ(refusal([](nlohmann::json& j) { j["points"] = 1; }),
            plan_path + ": point must be an integer from 0 to 0");
  EXPECT_EQ(refusal([](nlohmann::json& j) { j["tasks"][1]["point"] = -1; }),
            plan_path + ": point must be an integer from 0 to 1");
  EXPECT_EQ(refusal([](nlohmann::json& j) { j["tasks"][1]["point"] = 0; }),
            plan_path +
                ": task 1 is out of order, names a missing data set or point, or differs from its "
                "point's parameters");
  EXPECT_EQ(refusal([](nlohmann::json& j) { j["tasks"][1]["index"] = 0; }),
            plan_path +
                ": task 1 is out of order, names a missing data set or point, or differs from its "
                "point's parameters");
  EXPECT_EQ(refusal([](nlohmann::json& j) { j["tasks"][0]["dataset"] = 1; }),
            plan_path +
                ": task 0 is out of order, names a missing data set or point, or differs from its "
                "point's parameters");
  EXPECT_EQ(refusal([](nlohmann::json& j) { j["spec"]["goal"] = "minimise"; }),
            plan_path + ": goal 'minimise' is not one the sweep knows");
  EXPECT_EQ(refusal([](nlohmann::json& j) { j["spec"]["halving_rate"] = 1.5; }),
            plan_path + ": halving_rate must be a number from 2 to 100");
  EXPECT_EQ(refusal([](nlohmann::json& j) { j["spec"]["objective"] = "map_ate_m +"; }),
            plan_path + ": objective: cannot read the objective 'map_ate_m +' near character 12");

  // Both runs succeeded, then the base configuration was damaged: collecting names plan.json
  // and still writes every run's row.
  for (int i = 0; i < 2; ++i) {
    const std::string run = dir + "/runs/0000" + std::to_string(i);
    Write(fs::relative(run + "/status.json", Scratch().path()).string(),
          R"({"status": "ok", "exit_code": 0, "wall_s": 1.5, "error": ""})");
    Write(fs::relative(run + "/summary.json", Scratch().path()).string(),
          "{\"map_ate_m\": " + std::to_string(2 - i) + ", \"templates\": 4}");
  }
  refusal([](nlohmann::json& j) { j["spec"]["base_config"] = "[fused]\nrecency_s = [\n"; });
  StatusOr<CollectReport> collected = Collect(dir);
  ASSERT_FALSE(collected.ok());
  EXPECT_EQ(collected.status().message().rfind(plan_path + ": best point 1: ", 0), 0u)
      << collected.status().message();
  std::ifstream results(dir + "/results.csv");
  std::string line;
  int rows = 0;
  while (std::getline(results, line)) ++rows;
  EXPECT_EQ(rows, 3);  // the header and both runs
  EXPECT_FALSE(fs::exists(dir + "/best.toml"));
}

}  // namespace
}  // namespace ratslam::sweep
