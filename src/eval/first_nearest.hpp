#pragma once
// numpy's argmin of |value(k) - target| over k in [begin, end) for a non-decreasing value(k), found by
// bisection: the first index of the smallest difference, as a linear scan would give it.
#include <cmath>
#include <cstddef>

namespace mcslam::detail {

template <typename Value>
std::size_t firstNearest(std::size_t begin, std::size_t end, const Value& value, double target) {
  // First k with value(k) >= target.
  std::size_t lo = begin, hi = end;
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (value(mid) < target)
      lo = mid + 1;
    else
      hi = mid;
  }
  const std::size_t above = lo;
  if (above == begin) return begin;
  // First index of the run holding the largest value below target.
  const double below_value = value(above - 1);
  lo = begin;
  hi = above - 1;
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (value(mid) < below_value)
      lo = mid + 1;
    else
      hi = mid;
  }
  const std::size_t below = lo;
  if (above == end) return below;
  return std::abs(value(below) - target) <= std::abs(value(above) - target) ? below : above;
}

}  // namespace mcslam::detail
