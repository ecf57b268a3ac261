#include "apps/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <iostream>

namespace ratslam::apps {

ProgressPrinter::ProgressPrinter(std::FILE* stream, bool quiet, int terminal, const Clock* clock)
    : stream_(stream),
      quiet_(quiet),
      terminal_(terminal >= 0 ? terminal != 0 : ::isatty(::fileno(stream)) != 0),
      clock_(clock ? clock : &steady_) {}

std::string ProgressPrinter::Duration(double seconds) {
  const long total = std::lround(std::max(0.0, seconds));
  char buffer[32];
  if (total >= 3600) {
    std::snprintf(buffer, sizeof buffer, "%ldh%02ldm", total / 3600, total / 60 % 60);
  } else if (total >= 60) {
    std::snprintf(buffer, sizeof buffer, "%ldm%02lds", total / 60, total % 60);
  } else {
    std::snprintf(buffer, sizeof buffer, "%ld s", total);
  }
  return buffer;
}

void ProgressPrinter::Update(const ProgressUpdate& p) {
  if (quiet_) return;
  const size_t comma = p.phase.find(',');
  const std::string phase = p.phase.substr(0, comma);
  const std::string detail = comma == std::string::npos ? "" : p.phase.substr(comma + 1);
  const double now = clock_->Seconds();
  // A terminal line is redrawn at most ten times a second (a fast phase would otherwise
  // write thousands), and always at a new phase or detail and at the end.
  bool print = terminal_ && now - last_draw_s_ >= 0.1;
  if (phase != phase_ || last_tenth_ < 0) {
    if (drew_) Finish();
    phase_ = phase;
    phase_start_s_ = now;
    first_done_ = p.done;
    last_tenth_ = -1;
    print = true;
  }
  if (detail != detail_) print = true;
  detail_ = detail;
  const int tenth = p.total > 0 ? static_cast<int>(p.done * 10 / p.total) : -1;
  if (tenth > last_tenth_ && !terminal_) print = true;  // plain lines: every tenth
  if (terminal_ && p.total > 0 && p.done >= p.total) print = true;
  last_tenth_ = std::max(last_tenth_, tenth);
  last_ = p;
  if (print) Print(p, now, !terminal_);
}

void ProgressPrinter::Print(const ProgressUpdate& p, double now, bool end_line) {
  last_draw_s_ = now;
  const double elapsed = now - phase_start_s_;
  std::string line = phase_ + ":";
  char buffer[160];
  if (p.total > 0) {
    std::snprintf(buffer, sizeof buffer, " %5.1f%% %llu/%llu", 100.0 * p.done / p.total,
                  static_cast<unsigned long long>(p.done),
                  static_cast<unsigned long long>(p.total));
  } else {
    std::snprintf(buffer, sizeof buffer, " %llu", static_cast<unsigned long long>(p.done));
  }
  line += buffer;
  if (p.data_time_s >= 0) {
    std::snprintf(buffer, sizeof buffer, ", data time %.1f s", p.data_time_s);
    line += buffer;
  }
  line += ", " + Duration(elapsed) + " elapsed";
  const uint64_t fresh = p.done - std::min(p.done, first_done_);
  if (fresh > 0 && elapsed > 0) {
    const double rate = fresh / elapsed;
    std::snprintf(buffer, sizeof buffer, rate >= 100 ? ", %.0f/s" : ", %.3g/s", rate);
    line += buffer;
    if (p.total > p.done) line += ", ETA " + Duration((p.total - p.done) / rate);
  }
  if (!detail_.empty()) line += "," + detail_;
  if (terminal_ && !end_line) {
    // Redrawn in place; the padding clears a longer previous line.
    std::fprintf(stream_, "\r%-100s", line.c_str());
    drew_ = true;
  } else {
    std::fprintf(stream_, "%s%s\n", drew_ ? "\r" : "", line.c_str());
    drew_ = false;
  }
  std::fflush(stream_);
}

void ProgressPrinter::Finish() {
  if (quiet_) return;
  if (drew_) {
    std::fprintf(stream_, "\n");
    drew_ = false;
  } else if (!terminal_ && !phase_.empty() && last_.total > 0 && last_.done < last_.total) {
    // A phase that ended early (interrupted) says where.
    Print(last_, clock_->Seconds(), true);
  }
  last_tenth_ = -1;
  phase_.clear();
}

void PrintOutcome(bool json_flag, bool quiet, const std::string& json, const std::string& human) {
  if (json_flag || (!quiet && !::isatty(STDOUT_FILENO))) {
    std::cout << json;
  } else if (!quiet) {
    std::cout << human;
  }
}

}  // namespace ratslam::apps
