#pragma once
// The median of a few numbers (the mean of the two middle ones for an even count), for the online
// checks that compare NDT with the odometry and the fixes: a single bad value does not move it.
#include <algorithm>
#include <vector>

namespace coloc::pipeline {

inline double median(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  if (v.size() % 2) return *mid;
  return 0.5 * (*mid + *std::max_element(v.begin(), mid));
}

}  // namespace coloc::pipeline
