#pragma once
// Time along a route: a speed profile under speed, turn-rate, lateral and longitudinal acceleration limits,
// starting and ending at rest, with pauses at given arc lengths. Gives the arc length s(t).
#include <vector>

#include "route_curve.hpp"

namespace mcslam::sim {

struct SpeedLimits {
  double cruise = 1.0;         // m/s
  double max_yaw_rate = 0.87;  // rad/s
  double lateral_accel = 0.9;  // m/s^2
  double accel = 0.5;          // m/s^2 (speeding up and slowing down)
};

class ArcTiming {
 public:
  ArcTiming(const RouteCurve& curve, const SpeedLimits& limits, const std::vector<double>& stops, double dwell);
  double duration() const { return t_.back(); }
  double arcAt(double t) const;  // clamped to [0, length]

 private:
  std::vector<double> t_, s_;  // samples of s(t), t non-decreasing
};

}  // namespace mcslam::sim
