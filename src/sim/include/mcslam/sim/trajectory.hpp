#pragma once
// Simulated motions, defined in physical time (seconds from the start), so the frame rate only changes sampling.
//
//  ground    a planar ground robot following the world's route loop: about 1 m/s on straights, slowing into
//            corners where it turns at up to ~50 deg/s, stopping for 2 s at the route's stops, with floor
//            vibration and door-threshold bumps; the rig centre rides 1.0 m above the floor. Starts and ends at
//            rest at the same pose.
//  handheld  a person walking the same loop with the rig held at 1.45 m: smooth 6-DoF motion with step bob,
//            sway, looking around (yaw +-15 deg) and pitch/roll wobble; closes on itself.
//  file:PATH a TUM trajectory (t tx ty tz qx qy qz qw) of the rig body in the world (z up), interpolated
//            (linear / slerp); time 0 is its first stamp and the written stamps keep its time base.
#include <memory>
#include <string>
#include <vector>

#include "mcslam/core/se3.hpp"
#include "mcslam/core/time.hpp"
#include "mcslam/sim/world.hpp"

namespace mcslam::sim {

class SimTrajectory {
 public:
  virtual ~SimTrajectory() = default;
  // Length in seconds; poses are clamped to [0, duration].
  virtual double duration() const = 0;
  // Pose of the rig body in the world at t seconds from the start. T_v_b is the rig's mount on the platform
  // (rigMount); file trajectories give the body pose directly and ignore it.
  virtual SE3 bodyPose(double t, const SE3& T_v_b) const = 0;
  // Stamp of t = 0 in written data (nanoseconds).
  virtual Timestamp startStamp() const { return 1'000'000'000; }
  virtual std::string description() const = 0;
};

// A trajectory of the platform (x forward, y left, z up); the body follows through the mount.
class PlatformTrajectory : public SimTrajectory {
 public:
  virtual SE3 platformPose(double t) const = 0;  // T_w_v
  SE3 bodyPose(double t, const SE3& T_v_b) const override { return platformPose(t) * T_v_b; }
};

struct GroundOptions {
  double cruise_speed = 1.0;       // m/s on straights
  double max_yaw_rate_deg = 50.0;  // turn-rate limit that sets corner speeds
  double lateral_accel = 0.9;      // m/s^2 limit in corners
  double accel = 0.5;              // m/s^2 speeding up and slowing down
  double stop_seconds = 2.0;       // pause at each of the route's stops
  double height = 1.0;             // rig centre above the floor, m
  bool bumps = true;               // vibration and door-threshold bumps
};

struct HandheldOptions {
  double speed = 1.0;    // walking speed, m/s
  double height = 1.45;  // rig centre above the floor, m
};

// Ground robot on the world's route. Throws InputError when the route is not clear of the geometry.
std::shared_ptr<const PlatformTrajectory> makeGroundTrajectory(const World& world, uint64_t seed,
                                                               const GroundOptions& options = {});
std::shared_ptr<const PlatformTrajectory> makeHandheldTrajectory(const World& world, uint64_t seed,
                                                                 const HandheldOptions& options = {});
// Throws InputError naming the file (and line) when it cannot be read or has fewer than 2 poses.
std::shared_ptr<const SimTrajectory> makeFileTrajectory(const std::string& tum_path);

// "ground", "handheld" or "file:PATH"; throws InputError naming an unknown kind.
std::shared_ptr<const SimTrajectory> makeTrajectory(const std::string& spec, const World& world, uint64_t seed);
std::vector<std::string> trajectoryNames();  // {"ground", "handheld", "file:PATH"}
std::string describeTrajectories();          // for --help

// Yaw rate of the platform's forward axis about the world z axis, deg/s, by central differences (for tests and
// reports).
double yawRateDeg(const SimTrajectory& traj, const SE3& T_v_b, double t, double dt = 0.01);

}  // namespace mcslam::sim
