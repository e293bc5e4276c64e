#pragma once
// Summary statistics of an error sequence, with numpy's conventions (evo): population std, the median
// averages the two middle values of an even count.
#include <cstddef>
#include <utility>
#include <vector>

namespace mcslam {

struct ErrorStats {
  std::size_t count = 0;
  double rmse = 0, mean = 0, median = 0, std = 0, min = 0, max = 0, sse = 0;
};

// Zero count and zeros for an empty sequence.
ErrorStats computeErrorStats(const std::vector<double>& errors);

// The values at the `share` and 1 - `share` quantiles (nearest rank) of a non-empty sequence: its range without
// the outermost `share` at each end, so that a few far outliers do not set it.
std::pair<double, double> centralRange(std::vector<double> values, double share);

}  // namespace mcslam
