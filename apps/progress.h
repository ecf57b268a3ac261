// Progress output for long replays: a bar on a terminal, a line every ten percent otherwise.
#ifndef RATSLAM_APPS_PROGRESS_H_
#define RATSLAM_APPS_PROGRESS_H_

#include <cstdio>
#include <string>

#include "common/progress.h"

namespace ratslam {

class ProgressPrinter : public ProgressSink {
 public:
  // Writes to `stream` (normally stderr); `quiet` prints nothing.
  ProgressPrinter(std::FILE* stream, bool quiet);
  void Update(const ProgressUpdate& progress) override;
  void Finish() override;

 private:
  std::FILE* stream_;
  bool quiet_;
  bool terminal_;
  int last_decile_ = -1;
  bool drew_bar_ = false;
};

}  // namespace ratslam

#endif  // RATSLAM_APPS_PROGRESS_H_
