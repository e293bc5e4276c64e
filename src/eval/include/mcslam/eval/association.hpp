#pragma once
// Timestamp association of two trajectories, as evo does it (evo/core/sync.py, "nearest_time"):
// the trajectory with fewer poses drives; each of its stamps takes the nearest stamp of the other one
// (the first on a tie) when they are at most max_diff apart. A pose of the longer trajectory may serve
// two poses of the shorter one. Differences are taken in double seconds like evo's numpy arrays, so
// the same pairs come out even for stamps that sit exactly max_diff apart.
#include <cstddef>
#include <vector>

#include "mcslam/dataset/trajectory.hpp"

namespace mcslam {

struct TimeAssociation {
  std::vector<std::size_t> ref;  // indices into the reference, one per pair
  std::vector<std::size_t> est;  // indices into the estimate, same length
  std::size_t size() const { return ref.size(); }
};

// est_offset_s is added to the estimate's stamps before matching (evo's --t_offset). Empty when nothing
// matches; the caller names the files in its error.
TimeAssociation associateByTime(const Trajectory& ref, const Trajectory& est, double max_diff_s,
                                double est_offset_s = 0.0);

// The double that evo's parser gives for a stamp: the decimal text of the exact nanoseconds, correctly rounded.
double stampSeconds(Timestamp t);

}  // namespace mcslam
