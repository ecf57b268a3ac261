// Progress of a long step (replay, simulation, evaluation, training), reported by library code
// through this interface; the command line draws it, tests record it, and nothing prints by
// default.
#ifndef RATSLAM_COMMON_PROGRESS_H_
#define RATSLAM_COMMON_PROGRESS_H_

#include <cstdint>
#include <string>

namespace ratslam {

struct ProgressUpdate {
  std::string phase;  // "replay", "visual words of map", "queries", ...
  uint64_t done = 0;
  uint64_t total = 0;         // 0 when unknown
  double data_time_s = -1.0;  // data time reached, when the step has one
};

class ProgressSink {
 public:
  virtual ~ProgressSink() = default;
  virtual void Update(const ProgressUpdate& update) = 0;
  // The phase ended (a bar on a terminal gets its line break).
  virtual void Finish() {}
};

class SilentProgress : public ProgressSink {
 public:
  void Update(const ProgressUpdate&) override {}
};

}  // namespace ratslam

#endif  // RATSLAM_COMMON_PROGRESS_H_
