// Sweeps on a Slurm cluster: job-array scripts and their submission (sweep/sweep.h).
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
namespace {

std::string ShellQuoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// "0-3,7,9-10" from ascending numbers.
std::string Ranges(const std::vector<int>& numbers) {
  std::string out;
  for (size_t i = 0; i < numbers.size();) {
    size_t j = i;
    while (j + 1 < numbers.size() && numbers[j + 1] == numbers[j] + 1) ++j;
    out += (out.empty() ? "" : ",") + std::to_string(numbers[i]);
    if (j > i) out += "-" + std::to_string(numbers[j]);
    i = j + 1;
  }
  return out;
}

// Runs `argv` (found on PATH) and returns what it wrote to stdout; fails on a non-zero exit.
StatusOr<std::string> Capture(const std::vector<std::string>& args) {
  int fds[2];
  if (pipe(fds) != 0) return Status::Error("pipe: " + std::string(std::strerror(errno)));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_addclose(&actions, fds[0]);
  std::vector<std::string> copy = args;
  std::vector<char*> argv;
  for (std::string& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(fds[1]);
  if (rc != 0) {
    close(fds[0]);
    return Status::Error(args[0] + ": cannot start: " + std::strerror(rc));
  }
  std::string out;
  char buffer[4096];
  ssize_t n;
  while ((n = read(fds[0], buffer, sizeof buffer)) > 0) out.append(buffer, static_cast<size_t>(n));
  close(fds[0]);
  int wait_status = 0;
  waitpid(pid, &wait_status, 0);
  if (!WIFEXITED(wait_status) || WEXITSTATUS(wait_status) != 0) {
    return Status::Error(args[0] + " failed (exit " +
                         std::to_string(WIFEXITED(wait_status) ? WEXITSTATUS(wait_status) : -1) +
                         ")");
  }
  return out;
}

}  // namespace

StatusOr<SlurmJobs> WriteSlurmScripts(const std::string& dir, const SlurmOptions& options) {
  StatusOr<std::vector<TaskOutcome>> outcomes = ReadOutcomes(dir);
  if (!outcomes.ok()) return outcomes.status();
  if (options.chunk < 1) return Status::Error("chunk must be at least 1");
  std::vector<int> elements;  // array elements with a pending task
  for (const TaskOutcome& o : *outcomes) {
    const int element = o.index / options.chunk;
    if (o.status == "pending" && (elements.empty() || elements.back() != element)) {
      elements.push_back(element);
    }
  }
  if (elements.empty()) return Status::Error(dir + ": no pending task");
  const std::string folder = fs::absolute(dir).lexically_normal().string();
  std::error_code ec;
  fs::create_directories(fs::path(folder) / "slurm" / "logs", ec);
  if (ec) return Status::Error(folder + "/slurm: cannot create folder: " + ec.message());
  SlurmJobs jobs;
  jobs.array_spec = Ranges(elements);
  if (options.max_parallel > 0) jobs.array_spec += "%" + std::to_string(options.max_parallel);
  std::string common;
  if (!options.partition.empty()) common += "#SBATCH --partition=" + options.partition + "\n";
  if (!options.time.empty()) common += "#SBATCH --time=" + options.time + "\n";
  if (!options.mem.empty()) common += "#SBATCH --mem=" + options.mem + "\n";
  for (const std::string& a : options.sbatch_args) {
    if (a.find('\n') != std::string::npos) {
      return Status::Error("sbatch argument with a line break");
    }
    common += "#SBATCH " + a + "\n";
  }
  const std::string logs = folder + "/slurm/logs/";
  const std::string array =
      "#!/bin/sh\n#SBATCH --job-name=ratslam-sweep\n#SBATCH --array=" + jobs.array_spec +
      "\n#SBATCH --output=" + logs + "task-%a.out\n" + common + "exec " +
      ShellQuoted(options.program) + " sweep task " + ShellQuoted(folder) + " --chunk " +
      std::to_string(options.chunk) + "\n";
  const std::string collect =
      "#!/bin/sh\n#SBATCH --job-name=ratslam-sweep-collect\n#SBATCH "
      "--output=" +
      logs + "collect.out\n" + common + "exec " + ShellQuoted(options.program) + " sweep collect " +
      ShellQuoted(folder) + "\n";
  jobs.array_script = folder + "/slurm/array.sh";
  jobs.collect_script = folder + "/slurm/collect.sh";
  RATSLAM_RETURN_IF_ERROR(
      WriteFilesAtomically({{jobs.array_script, array}, {jobs.collect_script, collect}}));
  return jobs;
}

Status SubmitSlurm(SlurmJobs* jobs) {
  auto job_id = [](const std::string& parsable) {
    std::string id = parsable.substr(0, parsable.find_first_of(";\n"));
    return id;
  };
  StatusOr<std::string> array = Capture({"sbatch", "--parsable", jobs->array_script});
  if (!array.ok()) return array.status();
  jobs->array_job = job_id(*array);
  if (jobs->array_job.empty()) return Status::Error("sbatch printed no job id");
  StatusOr<std::string> collect = Capture(
      {"sbatch", "--parsable", "--dependency=afterany:" + jobs->array_job, jobs->collect_script});
  if (!collect.ok()) return collect.status();
  jobs->collect_job = job_id(*collect);
  return Status::Ok();
}

}  // namespace ratslam::sweep
