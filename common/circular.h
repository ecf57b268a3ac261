// Helpers for quantities that wrap around: angles and toroidal cell coordinates.
#ifndef RATSLAM_COMMON_CIRCULAR_H_
#define RATSLAM_COMMON_CIRCULAR_H_

#include <cmath>
#include <numbers>

namespace ratslam {

// Wraps an integer index into [0, size).
inline int WrapIndex(long long index, int size) {
  long long wrapped = index % size;
  return static_cast<int>(wrapped < 0 ? wrapped + size : wrapped);
}

// Wraps a real coordinate into [0, size).
inline double WrapCoordinate(double value, double size) {
  double wrapped = std::fmod(value, size);
  if (wrapped < 0.0) wrapped += size;
  return wrapped >= size ? 0.0 : wrapped;
}

// Signed shortest difference a - b on a circle of circumference `size`, in [-size/2, size/2).
inline double CircularDifference(double a, double b, double size) {
  return WrapCoordinate(a - b + 0.5 * size, size) - 0.5 * size;
}

// Wraps an angle into [-pi, pi).
inline double WrapAngle(double angle_rad) {
  return CircularDifference(angle_rad, 0.0, 2.0 * std::numbers::pi);
}

// WrapAngle, bit for bit, without fmod for angles in [-3 pi, 3 pi) (a sum or difference of two
// wrapped angles): fmod is exact, so one conditional subtraction or addition of 2 pi performs the
// same operations (Sterbenz: y - 2 pi is exact for y in [2 pi, 4 pi)). Hot loops use it.
inline double WrapAngleNear(double angle_rad) {
  constexpr double kPi = std::numbers::pi;
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  double y = angle_rad + kPi;
  if (!(y > -kTwoPi && y < 2.0 * kTwoPi)) return WrapAngle(angle_rad);  // also NaN
  if (y >= kTwoPi) {
    y -= kTwoPi;
  } else if (y < 0.0) {
    y += kTwoPi;
  }
  if (y >= kTwoPi) y = 0.0;
  return y - kPi;
}

}  // namespace ratslam

#endif  // RATSLAM_COMMON_CIRCULAR_H_
