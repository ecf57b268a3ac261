// The median of a sample: the middle value, or the mean of the two middle values of an even
// count (so the same numbers give the same median in any order). 0 for an empty sample.
#ifndef RATSLAM_COMMON_MEDIAN_H_
#define RATSLAM_COMMON_MEDIAN_H_

#include <algorithm>
#include <cstddef>
#include <vector>

namespace ratslam {

inline double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const size_t mid = v.size() / 2;
  const auto middle = v.begin() + static_cast<std::ptrdiff_t>(mid);
  std::nth_element(v.begin(), middle, v.end());
  if (v.size() % 2 == 1) return *middle;
  return 0.5 * (*middle + *std::max_element(v.begin(), middle));
}

}  // namespace ratslam

#endif  // RATSLAM_COMMON_MEDIAN_H_
