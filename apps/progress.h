// The one progress display of every long step (replay, simulation, evaluation and its training
// phases, sweeps): the phase, done of total, elapsed time, rate and ETA. On a terminal the line
// is redrawn in place; otherwise a line is printed when a phase starts, at every tenth of it,
// and when it ends, so logs stay short. Text after a comma in a phase name is a detail ("3
// failed"): it is shown, and a changed detail prints a line, but it does not restart the phase.
#ifndef RATSLAM_APPS_PROGRESS_H_
#define RATSLAM_APPS_PROGRESS_H_

#include <cstdint>
#include <cstdio>
#include <string>

#include "common/clock.h"
#include "common/progress.h"

namespace ratslam::apps {

class ProgressPrinter : public ProgressSink {
 public:
  // Writes to `stream` (normally stderr); `quiet` prints nothing. `terminal` forces the style
  // (-1: ask the stream); `clock` (default: the steady clock) times the phases.
  ProgressPrinter(std::FILE* stream, bool quiet, int terminal = -1, const Clock* clock = nullptr);
  void Update(const ProgressUpdate& progress) override;
  void Finish() override;

  // "42 s", "3m05s", "1h02m".
  static std::string Duration(double seconds);

 private:
  // A redrawn line on a terminal unless `end_line`; a whole line otherwise.
  void Print(const ProgressUpdate& p, double now, bool end_line);

  std::FILE* stream_;
  bool quiet_;
  bool terminal_;
  SteadyClock steady_;
  const Clock* clock_;
  std::string phase_;   // before the comma
  std::string detail_;  // after it
  double phase_start_s_ = 0;
  uint64_t first_done_ = 0;  // done when the phase was first seen (resumed work has no rate)
  int last_tenth_ = -1;
  bool drew_ = false;  // a terminal line is open
  double last_draw_s_ = -1e300;
  ProgressUpdate last_;
};

// What a command prints at its end on stdout: `json` with --json, or when stdout is not a
// terminal (scripts), `human` (a few lines for people) on a terminal, nothing with --quiet
// (unless --json).
void PrintOutcome(bool json_flag, bool quiet, const std::string& json, const std::string& human);

}  // namespace ratslam::apps

#endif  // RATSLAM_APPS_PROGRESS_H_
