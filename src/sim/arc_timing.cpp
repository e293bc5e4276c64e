#include "arc_timing.hpp"

#include <algorithm>
#include <cmath>

namespace mcslam::sim {

ArcTiming::ArcTiming(const RouteCurve& curve, const SpeedLimits& lim, const std::vector<double>& stops, double dwell) {
  const int m = static_cast<int>(curve.points().size()) - 1;
  const double ds = curve.length() / m;
  std::vector<double> v(m + 1);
  std::vector<bool> stop_here(m + 1, false);
  for (double s : stops) stop_here[std::clamp(static_cast<int>(std::lround(s / ds)), 1, m - 1)] = true;
  for (int j = 0; j <= m; ++j) {
    Vec2 p;
    double heading, kappa;
    curve.at(j * ds, p, heading, kappa);
    const double k = std::max(std::abs(kappa), 1e-9);
    v[j] = std::min({lim.cruise, lim.max_yaw_rate / k, std::sqrt(lim.lateral_accel / k)});
    if (stop_here[j]) v[j] = 0;
  }
  v[0] = v[m] = 0;
  for (int j = 0; j < m; ++j) v[j + 1] = std::min(v[j + 1], std::sqrt(v[j] * v[j] + 2 * lim.accel * ds));
  for (int j = m; j > 0; --j) v[j - 1] = std::min(v[j - 1], std::sqrt(v[j] * v[j] + 2 * lim.accel * ds));
  t_.push_back(0);
  s_.push_back(0);
  double t = 0;
  for (int j = 0; j < m; ++j) {
    t += 2 * ds / std::max(v[j] + v[j + 1], 1e-9);
    t_.push_back(t);
    s_.push_back((j + 1) * ds);
    if (stop_here[j + 1] && dwell > 0) {
      t += dwell;
      t_.push_back(t);
      s_.push_back((j + 1) * ds);
    }
  }
}

double ArcTiming::arcAt(double t) const {
  if (t <= 0) return 0;
  if (t >= t_.back()) return s_.back();
  const auto it = std::upper_bound(t_.begin(), t_.end(), t);
  const std::size_t j = static_cast<std::size_t>(it - t_.begin());
  const double t0 = t_[j - 1], t1 = t_[j];
  const double f = t1 > t0 ? (t - t0) / (t1 - t0) : 1.0;
  return s_[j - 1] + f * (s_[j] - s_[j - 1]);
}

}  // namespace mcslam::sim
