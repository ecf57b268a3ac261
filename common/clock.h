// Wall time for sessions behind an interface, so that tests use a fake and results never depend
// on it (only the reported wall times do).
#ifndef RATSLAM_COMMON_CLOCK_H_
#define RATSLAM_COMMON_CLOCK_H_

#include <chrono>

namespace ratslam {

class Clock {
 public:
  virtual ~Clock() = default;
  // Seconds on a monotonic clock (differences only).
  virtual double Seconds() const = 0;
};

class SteadyClock : public Clock {
 public:
  double Seconds() const override {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }
};

}  // namespace ratslam

#endif  // RATSLAM_COMMON_CLOCK_H_
