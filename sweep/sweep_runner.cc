// Running a sweep's tasks on this machine: a pool of `ratslam` processes, orphans of a killed
// runner, successive halving (sweep/sweep.h).
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
#include <climits>
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

StatusOr<TaskOutcome> ReadOutcome(const std::string& dir, int index) {
  TaskOutcome o;
  o.index = index;
  o.status = "pending";
  const std::string path = RunFolder(dir, index) + "/status.json";
  if (!PathExists(path)) return o;
  StatusOr<std::string> text = ReadRegularFile(path, "run status", 1 << 20);
  if (!text.ok()) return text.status();
  try {
    const json j = json::parse(*text);
    o.status = j.at("status").get<std::string>();
    // json's own conversion of a fraction or an out-of-range number to int is undefined.
    const json& exit_code = j.at("exit_code");
    const json& wall_s = j.at("wall_s");
    if (!exit_code.is_number_integer() ||
        exit_code.get<int64_t>() != static_cast<int>(exit_code.get<int64_t>()) ||
        (exit_code.is_number_unsigned() && exit_code.get<uint64_t>() > INT_MAX) ||
        !wall_s.is_number() || !(wall_s.get<double>() >= 0.0)) {
      throw json::type_error::create(302, "exit_code or wall_s out of range", &j);
    }
    o.exit_code = static_cast<int>(exit_code.get<int64_t>());
    o.wall_s = wall_s.get<double>();
    o.error = j.at("error").get<std::string>();
    o.program = j.value("program", std::string());
    o.host = j.value("host", std::string());
  } catch (const json::exception&) {
    TaskOutcome pending;  // torn or damaged: the run is repeated
    pending.index = index;
    pending.status = "pending";
    return pending;
  }
  return o;
}

namespace {

struct Running {
  int index = 0;
  pid_t pid = -1;
  std::string program;
  std::chrono::steady_clock::time_point start;
};

std::string LastLine(const std::string& path) {
  std::ifstream in(path);
  std::string line, last;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  }
  return last;
}

// Processes other than this one with `folder` as one of their arguments (a run's --out).
std::vector<pid_t> ProcessesNaming(const std::string& folder) {
  std::vector<pid_t> found;
  std::error_code ec;
  for (fs::directory_iterator it("/proc", ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    pid_t pid = 0;
    const auto [rest, error] = std::from_chars(name.data(), name.data() + name.size(), pid);
    if (error != std::errc() || rest != name.data() + name.size() || pid <= 1 || pid == getpid()) {
      continue;
    }
    std::ifstream cmdline(it->path() / "cmdline", std::ios::binary);
    for (std::string arg; std::getline(cmdline, arg, '\0');) {
      if (arg == folder) {
        found.push_back(pid);
        break;
      }
    }
  }
  return found;
}

// Whether `pid` is a process that has not ended (a zombie has: it waits only to be reaped).
bool Alive(pid_t pid) {
  if (kill(pid, 0) != 0) return false;
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  std::getline(stat, line);
  const size_t paren = line.rfind(')');  // "pid (name) state ...": the name may hold spaces
  return paren == std::string::npos || paren + 2 >= line.size() || line[paren + 2] != 'Z';
}

// A run left behind by a killed sweep runner is still writing into its folder: ended before the
// folder is reused. It is found by its command line, which names the folder, not by the pid file
// the runner writes after starting it: a runner killed between the two leaves no pid file, and
// the orphan would otherwise write its outputs into the next attempt's folder (seen in CI: the
// next attempt refused to overwrite them).
void EndOrphan(const std::string& folder) {
  if (!PathExists(folder)) return;  // never started
  const std::vector<pid_t> orphans = ProcessesNaming(folder);
  for (pid_t pid : orphans) {
    kill(-pid, SIGKILL);  // its process group (runs start in their own)
    kill(pid, SIGKILL);
  }
  for (pid_t pid : orphans) {
    for (int i = 0; i < 500 && Alive(pid); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
}

// Starts task `index` as `program replay ...` in its own process group.
StatusOr<Running> Start(const Plan& plan, const std::string& dir, int index,
                        const std::string& program) {
  const Task& task = plan.tasks.at(index);
  const std::string folder = RunFolder(dir, index);
  EndOrphan(folder);
  std::error_code ec;
  fs::remove_all(folder, ec);  // a run that never ended starts again from nothing
  fs::create_directories(folder, ec);
  if (ec) return Status::Error(folder + ": cannot create folder: " + ec.message());
  StatusOr<fusion::PipelineOptions> config = TaskConfig(plan, task);
  if (!config.ok()) return config.status();
  const std::string config_path = folder + "/config.toml";
  RATSLAM_RETURN_IF_ERROR(
      WriteFileAtomically(config_path, io::PrintConfig(*config), /*flush_to_disk=*/false));
  std::vector<std::string> args = {program, plan.spec.command, "--config", config_path};
  const std::vector<std::string>& data = plan.spec.datasets[task.dataset];
  if (plan.spec.command == "evaluate") {
    args.insert(args.end(), {"--map", data.front(), "--query", data.back()});
  } else {
    for (const std::string& d : data) {
      args.push_back("--data");
      args.push_back(d);
    }
  }
  args.insert(args.end(), {"--out", folder, "--quiet"});
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, (folder + "/stdout.txt").c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, (folder + "/stderr.txt").c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attributes, 0);  // its own group: a terminal's Ctrl-C is ours
  // The run ends with this runner, even one killed with SIGKILL (ratslam asks the kernel for a
  // signal when its parent dies; see kEndWithParentVariable).
  std::vector<std::string> environment;
  const std::string marker = std::string(kEndWithParentVariable) + "=";
  for (char** e = environ; *e != nullptr; ++e) {
    if (std::string_view(*e).substr(0, marker.size()) != marker) environment.emplace_back(*e);
  }
  environment.push_back(marker + std::to_string(::getpid()));
  std::vector<char*> envp;
  for (std::string& e : environment) envp.push_back(e.data());
  envp.push_back(nullptr);
  Running r;
  r.index = index;
  r.program = program;
  r.start = std::chrono::steady_clock::now();
  const int rc =
      posix_spawn(&r.pid, program.c_str(), &actions, &attributes, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  if (rc != 0) return Status::Error(program + ": cannot start: " + std::strerror(rc));
  // Who writes into the folder (for people; EndOrphan finds a left-behind run by its command
  // line, which also covers a runner killed before this line).
  std::ofstream(folder + "/pid") << r.pid << "\n";
  return r;
}

// Records how a run ended; with keep = small, removes all but the small outputs.
Status Finish(const Plan& plan, const std::string& dir, const Running& r, int wait_status,
              bool timed_out, TaskOutcome* outcome) {
  const std::string folder = RunFolder(dir, r.index);
  outcome->index = r.index;
  outcome->wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - r.start).count();
  outcome->exit_code =
      WIFEXITED(wait_status) ? WEXITSTATUS(wait_status) : 128 + WTERMSIG(wait_status);
  outcome->status = timed_out ? "timeout" : outcome->exit_code == 0 ? "ok" : "failed";
  outcome->error = outcome->status == "ok" ? "" : LastLine(folder + "/stderr.txt");
  if (timed_out) {
    outcome->error = "no result after " + schema::TomlNumber(plan.spec.timeout_s) + " s";
  } else if (!WIFEXITED(wait_status) && outcome->error.empty()) {
    outcome->error = std::string("killed by signal ") + strsignal(WTERMSIG(wait_status));
  }
  if (!plan.spec.keep_all && outcome->status == "ok") {
    static const std::set<std::string> kKept = {"summary.json", "evaluation.json",
                                                "config.toml",  "trajectory_tum.txt",
                                                "stderr.txt",   "pid"};
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(folder, ec)) {
      if (!kKept.count(entry.path().filename().string())) fs::remove_all(entry.path(), ec);
    }
  }
  char host[256] = "";
  gethostname(host, sizeof host - 1);
  outcome->program = r.program;
  outcome->host = host;
  const json status = {{"status", outcome->status},   {"exit_code", outcome->exit_code},
                       {"wall_s", outcome->wall_s},   {"error", outcome->error},
                       {"program", outcome->program}, {"host", outcome->host}};
  // Not flushed to disk (a flush per run cost more than the run itself on short replays): a
  // status torn by a power cut reads as pending and the run is repeated, never lost.
  return WriteFileAtomically(folder + "/status.json", status.dump(1) + "\n",
                             /*flush_to_disk=*/false);
}

// True when the run was ended by a stop request (it runs again next time, unrecorded).
bool Interrupted(int wait_status) {
  if (WIFSIGNALED(wait_status)) {
    const int s = WTERMSIG(wait_status);
    return s == SIGINT || s == SIGTERM;
  }
  return WIFEXITED(wait_status) && WEXITSTATUS(wait_status) == 130;
}

}  // namespace

StatusOr<std::vector<TaskOutcome>> ReadOutcomes(const std::string& dir) {
  StatusOr<Plan> plan = ReadPlan(dir);
  if (!plan.ok()) return plan.status();
  std::vector<TaskOutcome> out;
  for (const Task& t : plan->tasks) {
    StatusOr<TaskOutcome> o = ReadOutcome(dir, t.index);
    if (!o.ok()) return o.status();
    out.push_back(*o);
  }
  return out;
}

// The objective of a run, when it succeeded and its summary has it (defined with Collect).
std::optional<double> RunObjective(const Plan& plan, const std::string& dir, int index);

namespace {

// Runs the tasks of `queue` (all pending), options.jobs at a time, adding to `report`; `total`
// only feeds the progress line.
Status RunQueue(const Plan& plan, const std::string& dir, const std::vector<int>& queue,
                const RunOptions& options, int total, RunReport* report) {
  std::vector<Running> running;
  size_t next = 0;
  auto stopping = [&] { return options.stop_requested && options.stop_requested->load(); };
  auto show = [&] {
    if (!options.progress) return;
    // "sweep, N failed": the failures are a detail of the phase (see apps/progress.h).
    options.progress->Update({"sweep, " + std::to_string(report->failed) + " failed",
                              static_cast<uint64_t>(report->done + report->skipped),
                              static_cast<uint64_t>(total)});
  };
  Status error;
  while (error.ok() && ((next < queue.size() && !stopping()) || !running.empty())) {
    while (error.ok() && !stopping() && next < queue.size() &&
           static_cast<int>(running.size()) < std::max(1, options.jobs)) {
      StatusOr<Running> r = Start(plan, dir, queue[next++], options.program);
      if (!r.ok()) {
        error = r.status();
        break;
      }
      running.push_back(*r);
      show();
    }
    bool changed = false;
    for (size_t i = 0; i < running.size();) {
      Running& r = running[i];
      int wait_status = 0;
      const pid_t done = waitpid(r.pid, &wait_status, WNOHANG);
      const double age =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - r.start).count();
      const bool timed_out = plan.spec.timeout_s > 0.0 && age > plan.spec.timeout_s;
      if (done == 0 && (timed_out || stopping())) {
        kill(-r.pid, timed_out ? SIGKILL : SIGTERM);
        waitpid(r.pid, &wait_status, 0);
      } else if (done == 0) {
        ++i;
        continue;
      }
      if (!timed_out && (stopping() || Interrupted(wait_status))) {
        ++report->pending;  // unrecorded: it runs again next time
      } else {
        TaskOutcome outcome;
        Status s = Finish(plan, dir, r, wait_status, timed_out, &outcome);
        if (!s.ok() && error.ok()) error = s;
        ++report->done;
        if (outcome.status != "ok") ++report->failed;
      }
      running.erase(running.begin() + static_cast<std::ptrdiff_t>(i));
      changed = true;
    }
    if (changed) show();
    if (!running.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  for (const Running& r : running) {  // after an error: end what is still running
    kill(-r.pid, SIGTERM);
    int wait_status = 0;
    waitpid(r.pid, &wait_status, 0);
    ++report->pending;
  }
  report->pending += static_cast<int>(queue.size() - next);
  return error;
}

// Successive halving (Jamieson and Talwalkar 2016) over data sets: every point runs on a few
// data sets, the best 1/rate of the points go on to rate times as many, until the survivors
// have run on all of them. Data sets enter in a seeded random order. Deterministic given the
// runs' results, so a resumed sweep makes the same decisions. Writes DIR/search.json.
Status RunHalving(const Plan& plan, const std::string& dir, const RunOptions& options,
                  RunReport* report) {
  const SweepSpec& spec = plan.spec;
  const int datasets = static_cast<int>(spec.datasets.size());
  const double rate = spec.halving_rate;
  std::vector<int> order(datasets);
  for (int d = 0; d < datasets; ++d) order[d] = d;
  Random random(spec.seed ^ 0x5eedULL);
  for (int i = datasets - 1; i > 0; --i) {
    std::swap(order[i], order[random.NextU64() % static_cast<uint64_t>(i + 1)]);
  }
  // Halvings: as many as the points need, but no more than the data sets allow.
  const int halvings = std::max(
      0, std::min(static_cast<int>(
                      std::ceil(std::log(std::max(1, plan.points)) / std::log(rate) - 1e-9)),
                  static_cast<int>(std::floor(std::log(datasets) / std::log(rate) + 1e-9))));
  int used = std::max(1, static_cast<int>(std::ceil(datasets / std::pow(rate, halvings))));
  std::vector<int> survivors(plan.points);
  for (int p = 0; p < plan.points; ++p) survivors[p] = p;
  std::map<std::pair<int, int>, int> task_of;  // (point, data set) -> task
  for (const Task& t : plan.tasks) task_of[{t.point, t.dataset}] = t.index;
  const bool minimize = spec.goal == "minimize";
  json rounds = json::array();
  int planned_runs = 0;
  while (true) {
    std::vector<int> queue;
    for (int p : survivors) {
      for (int k = 0; k < used; ++k) {
        const int index = task_of.at({p, order[k]});
        StatusOr<TaskOutcome> o = ReadOutcome(dir, index);
        if (!o.ok()) return o.status();
        if (o->status == "pending") queue.push_back(index);
      }
    }
    std::sort(queue.begin(), queue.end());
    planned_runs += static_cast<int>(queue.size());
    RATSLAM_RETURN_IF_ERROR(
        RunQueue(plan, dir, queue, options, static_cast<int>(plan.tasks.size()), report));
    if (report->pending > 0) return Status::Ok();  // stopped: the next run resumes this round
    // Each survivor's objective over the data sets used so far; a failed run ranks it last.
    std::vector<std::pair<double, int>> ranked;
    for (int p : survivors) {
      double sum = 0.0, worst = minimize ? -1e300 : 1e300;
      bool failed = false;
      for (int k = 0; k < used; ++k) {
        const std::optional<double> v = RunObjective(plan, dir, task_of.at({p, order[k]}));
        if (!v) {
          failed = true;
          break;
        }
        sum += *v;
        worst = minimize ? std::max(worst, *v) : std::min(worst, *v);
      }
      double value = spec.aggregate == "mean" ? sum / used : worst;
      if (failed) value = minimize ? 1e300 : -1e300;
      ranked.emplace_back(minimize ? value : -value, p);  // ascending is best first
    }
    std::sort(ranked.begin(), ranked.end());
    json round = {{"datasets", used}, {"points", survivors}, {"runs", queue.size()}};
    if (used >= datasets) {
      rounds.push_back(round);
      break;
    }
    const size_t keep =
        std::max<size_t>(1, static_cast<size_t>(std::ceil(survivors.size() / rate)));
    survivors.clear();
    for (size_t i = 0; i < keep && i < ranked.size(); ++i) survivors.push_back(ranked[i].second);
    std::sort(survivors.begin(), survivors.end());
    round["kept"] = survivors;
    rounds.push_back(round);
    used = std::min(datasets, static_cast<int>(std::ceil(used * rate)));
  }
  const json search = {{"search", "halving"},           {"rate", rate},
                       {"dataset_order", order},        {"rounds", rounds},
                       {"finalists", survivors},        {"runs", planned_runs},
                       {"grid_runs", plan.tasks.size()}};
  return WriteFileAtomically((fs::path(dir) / "search.json").string(), search.dump(1) + "\n");
}

}  // namespace

StatusOr<RunReport> RunSweep(const std::string& dir, const RunOptions& options) {
  StatusOr<Plan> plan = ReadPlan(dir);
  if (!plan.ok()) return plan.status();
  // Two runners on one folder would start every task twice and end each other's runs.
  StatusOr<FolderLock> lock = FolderLock::Acquire(dir, "ratslam sweep run");
  if (!lock.ok()) return lock.status();
  RunReport report;
  Status status;
  if (plan->spec.search == "halving") {
    for (const Task& t : plan->tasks) {
      StatusOr<TaskOutcome> o = ReadOutcome(dir, t.index);
      if (!o.ok()) return o.status();
      if (o->status != "pending") ++report.skipped;
      if (o->status != "pending" && o->status != "ok") ++report.failed;
    }
    status = RunHalving(*plan, dir, options, &report);
  } else {
    std::vector<int> queue;
    for (const Task& t : plan->tasks) {
      StatusOr<TaskOutcome> o = ReadOutcome(dir, t.index);
      if (!o.ok()) return o.status();
      if (o->status == "pending") {
        queue.push_back(t.index);
      } else {
        ++report.skipped;
        if (o->status != "ok") ++report.failed;
      }
    }
    status = RunQueue(*plan, dir, queue, options, static_cast<int>(plan->tasks.size()), &report);
  }
  if (options.progress) options.progress->Finish();
  if (!status.ok()) return status;
  return report;
}

StatusOr<TaskOutcome> RunTask(const std::string& dir, int index, const std::string& program) {
  StatusOr<Plan> plan = ReadPlan(dir);
  if (!plan.ok()) return plan.status();
  if (index < 0 || index >= static_cast<int>(plan->tasks.size())) {
    return Status::Error(dir + ": no task " + std::to_string(index) + " (the plan has " +
                         std::to_string(plan->tasks.size()) + ")");
  }
  StatusOr<TaskOutcome> recorded = ReadOutcome(dir, index);
  if (!recorded.ok() || recorded->status != "pending") return recorded;
  // The same runner as a whole sweep's, with a queue of one: timeout, interruption and the
  // recorded outcome behave alike.
  RunOptions options;
  options.program = program;
  RunReport report;
  RATSLAM_RETURN_IF_ERROR(RunQueue(*plan, dir, {index}, options, 1, &report));
  return ReadOutcome(dir, index);
}

StatusOr<std::vector<TaskOutcome>> RunTasks(const std::string& dir, int first, int count,
                                            const std::string& program) {
  StatusOr<Plan> plan = ReadPlan(dir);
  if (!plan.ok()) return plan.status();
  const int total = static_cast<int>(plan->tasks.size());
  if (first < 0 || first >= total || count < 1) {
    return Status::Error(dir + ": no task " + std::to_string(first) + " (the plan has " +
                         std::to_string(total) + ")");
  }
  std::vector<TaskOutcome> outcomes;
  for (int i = first; i < std::min(total, first + count); ++i) {
    StatusOr<TaskOutcome> o = RunTask(dir, i, program);
    if (!o.ok()) return o.status();
    outcomes.push_back(*o);
  }
  return outcomes;
}

}  // namespace ratslam::sweep
