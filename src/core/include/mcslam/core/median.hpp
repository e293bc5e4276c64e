#pragma once
// Median of scratch that the caller owns (sized at start): no allocation, the first n values are reordered.
#include <algorithm>
#include <vector>

namespace mcslam {

inline double medianOf(std::vector<double>& v, int n) {
  std::nth_element(v.begin(), v.begin() + n / 2, v.begin() + n);
  return v[n / 2];
}

}  // namespace mcslam
