#pragma once
// A smooth closed path from a RouteSpec: the polygon's corners are rounded with circular arcs, the curvature is
// then smoothed (no jumps in yaw rate) and the small closure error this leaves is spread along the loop.
#include <vector>

#include "mcslam/sim/world.hpp"

namespace mcslam::sim {

class RouteCurve {
 public:
  explicit RouteCurve(const RouteSpec& spec, double smoothing = 0.8, double step = 0.01);

  double length() const { return length_; }
  // Position, heading (radians) and signed curvature (1/m) at arc length s (wrapped into [0, length)).
  void at(double s, Vec2& p, double& heading, double& curvature) const;
  // Arc lengths where the route says to stop (start of the corner's arc).
  const std::vector<double>& stops() const { return stops_; }
  // Samples every `step` metres (for clearance checks and distances).
  const std::vector<Vec2>& points() const { return points_; }
  // Shortest distance from q to the curve.
  double distanceTo(const Vec2& q) const;

 private:
  double step_ = 0.01, length_ = 0;
  std::vector<Vec2> points_;
  std::vector<double> heading_, curvature_;
  std::vector<double> stops_;
};

// Throws InputError naming the place when the route passes closer than `clearance` to static geometry (checked
// with horizontal rays at several heights) or when its samples are not connected in free space.
void checkRouteClearance(const World& world, const RouteCurve& curve, double clearance);

}  // namespace mcslam::sim
