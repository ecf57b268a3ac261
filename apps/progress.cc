#include "apps/progress.h"

#include <unistd.h>

namespace ratslam {

ProgressPrinter::ProgressPrinter(std::FILE* stream, bool quiet)
    : stream_(stream), quiet_(quiet), terminal_(::isatty(::fileno(stream)) != 0) {}

void ProgressPrinter::Update(const ProgressUpdate& p) {
  if (quiet_ || p.total == 0) return;
  const double fraction = static_cast<double>(p.done) / p.total;
  if (terminal_) {
    constexpr int kWidth = 40;
    const int filled = static_cast<int>(fraction * kWidth);
    std::fprintf(stream_, "\r[%s%s] %5.1f%%  %llu/%llu events  t=%.1f s",
                 std::string(filled, '#').c_str(), std::string(kWidth - filled, ' ').c_str(),
                 100.0 * fraction, static_cast<unsigned long long>(p.done),
                 static_cast<unsigned long long>(p.total), p.data_time_s);
    std::fflush(stream_);
    drew_bar_ = true;
    return;
  }
  const int decile = static_cast<int>(fraction * 10);
  if (decile > last_decile_) {
    last_decile_ = decile;
    std::fprintf(stream_, "progress: %3d%%  %llu/%llu events  data time %.1f s\n", decile * 10,
                 static_cast<unsigned long long>(p.done), static_cast<unsigned long long>(p.total),
                 p.data_time_s);
  }
}

void ProgressPrinter::Finish() {
  if (drew_bar_) std::fprintf(stream_, "\n");
  drew_bar_ = false;
}

}  // namespace ratslam
