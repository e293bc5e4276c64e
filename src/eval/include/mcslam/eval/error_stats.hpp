#pragma once
// Summary statistics of an error sequence, with numpy's conventions (evo): population std, the median
// averages the two middle values of an even count.
#include <cstddef>
#include <vector>

namespace mcslam {

struct ErrorStats {
  std::size_t count = 0;
  double rmse = 0, mean = 0, median = 0, std = 0, min = 0, max = 0, sse = 0;
};

// Zero count and zeros for an empty sequence.
ErrorStats computeErrorStats(const std::vector<double>& errors);

}  // namespace mcslam
