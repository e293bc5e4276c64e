#include "mcslam/eval/association.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "first_nearest.hpp"

namespace mcslam {

double stampSeconds(Timestamp t) {
  // Going through the decimal text gives the correctly rounded double of the exact value, which is what
  // evo's float parsing of the file gives (t * 1e-9 can be one ulp off, and near 1e9 s an ulp is 240 ns).
  char buf[48];
  const unsigned long long a = t < 0 ? 0ULL - static_cast<unsigned long long>(t) : static_cast<unsigned long long>(t);
  std::snprintf(buf, sizeof(buf), "%s%llu.%09llu", t < 0 ? "-" : "", a / 1000000000ULL, a % 1000000000ULL);
  return std::strtod(buf, nullptr);
}

namespace {

std::vector<double> secondsOf(const Trajectory& traj, double offset) {
  std::vector<double> s(traj.size());
  for (std::size_t i = 0; i < traj.size(); ++i) s[i] = stampSeconds(traj[i].t) + offset;
  return s;
}

// Index of the first minimum of |stamps[j] - t| (numpy argmin semantics).
std::size_t nearestIndex(const std::vector<double>& stamps, bool sorted, double t) {
  if (sorted)
    return detail::firstNearest(
        0, stamps.size(), [&](std::size_t j) { return stamps[j]; }, t);
  std::size_t best = 0;
  for (std::size_t j = 1; j < stamps.size(); ++j) {
    if (std::abs(stamps[j] - t) < std::abs(stamps[best] - t)) best = j;
  }
  return best;
}

}  // namespace

TimeAssociation associateByTime(const Trajectory& ref, const Trajectory& est, double max_diff_s, double est_offset_s) {
  TimeAssociation out;
  if (ref.empty() || est.empty()) return out;
  // The trajectory with fewer poses drives, so that none of its poses is lost (evo: the second one is
  // "longer" only when it has strictly more poses).
  const bool est_longer = est.size() > ref.size();
  const Trajectory& shorter = est_longer ? ref : est;
  const Trajectory& longer = est_longer ? est : ref;
  // evo adds the offset to the longer one's stamps, with the sign that keeps it on the estimate.
  const std::vector<double> s_short = secondsOf(shorter, 0.0);
  const std::vector<double> s_long = secondsOf(longer, est_longer ? est_offset_s : -est_offset_s);
  const bool sorted = std::is_sorted(s_long.begin(), s_long.end());
  for (std::size_t i = 0; i < s_short.size(); ++i) {
    const std::size_t j = nearestIndex(s_long, sorted, s_short[i]);
    if (std::abs(s_long[j] - s_short[i]) <= max_diff_s) {
      out.ref.push_back(est_longer ? i : j);
      out.est.push_back(est_longer ? j : i);
    }
  }
  return out;
}

}  // namespace mcslam
