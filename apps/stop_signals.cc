// SIGINT and SIGTERM for the commands (apps/cli.h: StopFlag, StopCooperatively).
#include <unistd.h>

#include <atomic>
#include <csignal>

#include "apps/cli.h"

namespace ratslam::apps {
namespace {

std::atomic<bool> g_stop_requested{false};
std::atomic<bool> g_cooperative{false};

extern "C" void OnSignal(int) { g_stop_requested.store(true); }

// A command that does not poll the stop flag ends at once; a second signal ends any command.
extern "C" void OnGuardedSignal(int) {
  if (!g_cooperative.load() || g_stop_requested.exchange(true)) ::_exit(kExitInterrupted);
}

}  // namespace

std::atomic<bool>& StopFlag() { return g_stop_requested; }
void StopCooperatively() { g_cooperative.store(true); }

void StopOnSignals() {
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
}

void StopOnSignalsGuarded() {
  std::signal(SIGINT, OnGuardedSignal);
  std::signal(SIGTERM, OnGuardedSignal);
}

}  // namespace ratslam::apps
