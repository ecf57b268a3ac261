// The `ratslam` program: parses the command line (apps/command_line.h), runs the command's
// handler, under an OutputGuard when it writes into a folder, and turns exceptions into exit codes.
#include <sys/prctl.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <iostream>
#include <opencv2/core/utility.hpp>
#include <string>
#include <variant>
#include <vector>

#include "apps/cli.h"
#include "apps/command_line.h"
#include "common/file_util.h"
#include "common/output_guard.h"
#include "sweep/sweep.h"

namespace {

// Runs a command that writes into the folder --out under an OutputGuard (common/output_guard.h):
// the folder is locked, a folder holding an earlier run's outputs is refused without --overwrite,
// the command writes into the guard's staging folder, and its outputs appear in --out together
// when it ends (kept aside in incomplete-run/ when it fails).
int RunGuarded(int (*handler)(const ratslam::apps::Arguments&),
               const ratslam::apps::Arguments& args) {
  using namespace ratslam;
  using namespace ratslam::apps;
  const std::string folder = args.Value("--out");
  const bool overwrite = args.values.count("--overwrite") > 0;
  std::vector<std::string> inputs;
  for (const char* flag : {"--data", "--load-map", "--config", "--map", "--query", "--wifi-map"}) {
    if (auto it = args.all.find(flag); it != args.all.end()) {
      inputs.insert(inputs.end(), it->second.begin(), it->second.end());
    }
  }
  auto fail = [](const Status& s) {
    std::cerr << MessagePrefix() << s.message() << "\n";
    return kExitError;
  };
  const std::string save_map = args.Value("--save-map");
  if (Status s = CheckReplaceable(save_map, overwrite, "--save-map"); !s.ok()) return fail(s);
  StatusOr<OutputGuard> guard = OutputGuard::Begin(folder, overwrite, inputs, args.command_line);
  if (!guard.ok()) return fail(guard.status());
  Arguments staged = args;
  staged.output_folder = folder;
  staged.values["--out"] = guard->staging();
  staged.all["--out"] = {guard->staging()};
  if (!save_map.empty()) {
    staged.values["--save-map"] = guard->Staged(save_map);
    staged.all["--save-map"] = {staged.values["--save-map"]};
  }
  StopOnSignalsGuarded();
  const int code = handler(staged);
  // Ends once the outputs are in place (a signal during the moves waits for them).
  std::signal(SIGINT, SIG_IGN);
  std::signal(SIGTERM, SIG_IGN);
  // A run stopped by a data error after writing its summary (a replay keeps its outputs up to
  // the last complete event, and its state to resume from) keeps them as an interrupted one does.
  OutputGuard::Outcome outcome = OutputGuard::Outcome::kFailed;
  if (code == kExitOk) {
    outcome = OutputGuard::Outcome::kSucceeded;
  } else if ((code == kExitInterrupted || code == kExitError) && guard->StagedSummary()) {
    outcome = OutputGuard::Outcome::kInterrupted;
  }
  StatusOr<OutputGuard::Report> report = guard->Finish(outcome);
  if (!report.ok()) {
    std::cerr << MessagePrefix() << "the outputs were not moved into " << folder << ": "
              << report.status().message() << "\n";
    return code == kExitOk ? kExitError : code;
  }
  if (!report->incomplete.empty()) {
    std::cerr << MessagePrefix() << "the unfinished run's files are in " << report->incomplete
              << " (" << folder << " itself is as it was)\n";
  }
  if (!report->removed.empty() && !args.quiet) {
    std::cerr << MessagePrefix() << "--overwrite removed " << report->removed.size()
              << " file(s) of the earlier run that this run did not write again\n";
  }
  return code;
}

int Dispatch(int argc, char** argv) {
  using namespace ratslam;
  using namespace ratslam::apps;
  std::variant<ParsedCommand, int> parsed = ParseCommandLine(argc, argv, std::cout, std::cerr);
  if (const int* code = std::get_if<int>(&parsed)) return *code;
  ParsedCommand& command = std::get<ParsedCommand>(parsed);
  command.args.command_line = ShellCommandLine(argc, argv);
  MessagePrefix() = "ratslam " + command.command + ": ";
  if (command.handler == nullptr) {
    std::cerr << MessagePrefix() << "internal error: no handler for '" << command.command << "'\n";
    return kExitInternal;
  }
  if (command.args.Value("--out").empty() || !command.guard_out) {
    return command.handler(command.args);
  }
  return RunGuarded(command.handler, command.args);
}

}  // namespace

// A run started by `sweep run` ends with its runner (sweep.h, kEndWithParentVariable): SIGTERM
// when the runner dies stops it as Ctrl-C would.
void EndWithParent() {
  const char* parent = std::getenv(ratslam::sweep::kEndWithParentVariable);
  if (parent == nullptr) return;
  ::prctl(PR_SET_PDEATHSIG, SIGTERM);
  if (std::to_string(::getppid()) != parent) std::raise(SIGTERM);  // the runner died already
}

// Expected failures come back as Status; an exception here is a bug or an exhausted machine
// (std::bad_alloc). Either way the program says so and exits non-zero instead of aborting.
int main(int argc, char** argv) {
  EndWithParent();
#if defined(RATSLAM_SANITIZED_BUILD)
  // OpenCV's parallel loops (the animation's MJPEG encoder, SIFT) start a TBB worker thread that
  // outlives its work and ends only during process exit, where it races LeakSanitizer's at-exit
  // check: "Tracer caught signal 11" and exit 1 (CI, --render --animate, twice in a row).
  // Sanitizer builds run OpenCV sequentially; its loops split work, never results.
  cv::setNumThreads(0);
#endif
  try {
    return Dispatch(argc, argv);
  } catch (const std::bad_alloc&) {
    std::cerr << ratslam::apps::MessagePrefix() << "out of memory\n";
  } catch (const std::exception& e) {
    std::cerr << ratslam::apps::MessagePrefix() << "internal error: " << e.what() << "\n";
  }
  return ratslam::apps::kExitInternal;
}
