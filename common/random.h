// A small seeded random generator whose sequence is the same on every platform and standard
// library (std::normal_distribution is not), so that a seed always gives the same data.
#ifndef RATSLAM_COMMON_RANDOM_H_
#define RATSLAM_COMMON_RANDOM_H_

#include <cmath>
#include <cstdint>
#include <numbers>

namespace ratslam {

class Random {
 public:
  explicit Random(uint64_t seed) : state_(seed) {}

  // SplitMix64 (Steele, Lea and Flood 2014).
  uint64_t NextU64() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1).
  double Uniform() { return static_cast<double>(NextU64() >> 11) * 0x1.0p-53; }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  // Standard normal by the Box-Muller transform.
  double Gaussian() {
    const double u1 = 1.0 - Uniform();  // in (0, 1]
    const double u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }
  double Gaussian(double mean, double sigma) { return mean + sigma * Gaussian(); }

 private:
  uint64_t state_;
};

}  // namespace ratslam

#endif  // RATSLAM_COMMON_RANDOM_H_
