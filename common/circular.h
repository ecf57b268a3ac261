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

// sin and cos of an angle that is mostly small (a rotation increment in a hot loop): a short
// series for |x| <= 1/16 (terms to x^11 and x^12, and to x^5 and x^4 for |x| <= 2^-10: the
// first omitted term is below 1e-19 in both ranges, under an ulp of the result), glibc's sincos
// beyond. Multiplications by folded coefficients, no division: it costs less than a sincos call.
inline void SinCosOfSmallAngle(double x, double* sin_x, double* cos_x) {
  if (!(std::abs(x) <= 0.0625)) {  // also NaN
    ::sincos(x, sin_x, cos_x);
    return;
  }
  // Taylor coefficients (-1)^k / (2k+1)! and (-1)^k / (2k)!.
  constexpr double s3 = -1.0 / 6, s5 = 1.0 / 120, s7 = -1.0 / 5040, s9 = 1.0 / 362880,
                   s11 = -1.0 / 39916800;
  constexpr double c2 = -1.0 / 2, c4 = 1.0 / 24, c6 = -1.0 / 720, c8 = 1.0 / 40320,
                   c10 = -1.0 / 3628800, c12 = 1.0 / 479001600;
  const double x2 = x * x;
  if (std::abs(x) <= 0x1p-10) {
    *sin_x = x + x * x2 * (s3 + x2 * s5);
    *cos_x = 1.0 + x2 * (c2 + x2 * c4);
    return;
  }
  *sin_x = x + x * x2 * (s3 + x2 * (s5 + x2 * (s7 + x2 * (s9 + x2 * s11))));
  *cos_x = 1.0 + x2 * (c2 + x2 * (c4 + x2 * (c6 + x2 * (c8 + x2 * (c10 + x2 * c12)))));
}

}  // namespace ratslam

#endif  // RATSLAM_COMMON_CIRCULAR_H_
