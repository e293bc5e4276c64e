// Trajectory properties the odometry tests rely on: the ground robot's loop in the indoor world is long (>= 60 m),
// turns fast (>= 30 deg/s) and ends where it started; the hand-held walk closes on itself too.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "mcslam/sim/rig_presets.hpp"
#include "mcslam/sim/trajectory.hpp"
#include "mcslam/sim/world.hpp"

namespace mcslam::sim {
namespace {

struct PathStats {
  double length = 0;         // metres travelled by the body
  double end_gap = 0;        // metres between first and last body position
  double end_angle_deg = 0;  // rotation between first and last body orientation
  double max_yaw_rate = 0;   // deg/s, platform heading
};

PathStats walk(const SimTrajectory& traj, const SE3& T_v_b) {
  PathStats s;
  const double dt = 0.01;
  const SE3 first = traj.bodyPose(0.0, T_v_b);
  Vec3 prev = first.t;
  for (double t = dt; t <= traj.duration() + 1e-9; t += dt) {
    const Vec3 p = traj.bodyPose(t, T_v_b).t;
    s.length += (p - prev).norm();
    prev = p;
    s.max_yaw_rate = std::max(s.max_yaw_rate, std::abs(yawRateDeg(traj, T_v_b, t)));
  }
  const SE3 last = traj.bodyPose(traj.duration(), T_v_b);
  s.end_gap = (last.t - first.t).norm();
  s.end_angle_deg = Eigen::AngleAxisd(first.R.transpose() * last.R).angle() * 180 / M_PI;
  return s;
}

// One test for both motions: building the indoor world is most of the time, and CTest runs every test alone.
TEST(SimTrajectories, IndoorGroundLoopIsLongTurnsFastAndClosesHandheldWalkClosesToo) {
  const auto world = makeWorld("indoor");
  const SE3 mount = rigMount(makePresetRig("isec"));

  const auto ground = makeGroundTrajectory(*world, 1);
  const PathStats s = walk(*ground, mount);
  EXPECT_GE(s.length, 60.0);
  EXPECT_LT(s.end_gap, 0.01) << "metres between start and end";
  EXPECT_LT(s.end_angle_deg, 0.5);
  EXPECT_GE(s.max_yaw_rate, 30.0);
  ::testing::Test::RecordProperty("length_m", std::to_string(s.length));
  ::testing::Test::RecordProperty("max_yaw_rate_deg_s", std::to_string(s.max_yaw_rate));

  const auto handheld = makeHandheldTrajectory(*world, 1);
  const PathStats h = walk(*handheld, mount);
  EXPECT_GE(h.length, 60.0);
  EXPECT_LT(h.end_gap, 0.01) << "hand-held: metres between start and end";
  EXPECT_LT(h.end_angle_deg, 0.5) << "hand-held";
}

}  // namespace
}  // namespace mcslam::sim
