// One number format for every text output (CSV, TUM, g2o, JSON-adjacent files): the shortest
// decimal text that reads back to the same double (std::to_chars without a precision), so a
// value written and read again is the value computed, and no file is padded with 17 digits
// where 3 say the same. NaN and infinities print as "nan", "inf" and "-inf".
#ifndef RATSLAM_COMMON_NUMBER_TEXT_H_
#define RATSLAM_COMMON_NUMBER_TEXT_H_

#include <charconv>
#include <string>

namespace ratslam {

inline std::string ShortestNumber(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

}  // namespace ratslam

#endif  // RATSLAM_COMMON_NUMBER_TEXT_H_
