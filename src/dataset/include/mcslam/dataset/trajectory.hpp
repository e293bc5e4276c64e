#pragma once
// Trajectories: time-stamped poses of the body in the world (T_w_b), read and written in the
// TUM format (`t tx ty tz qx qy qz qw`, seconds) and the KITTI format (12 numbers per line, row-major
// 3x4 [R|t], times in a separate file or implicit frame indices).
#include <string>
#include <vector>

#include "mcslam/core/se3.hpp"
#include "mcslam/core/time.hpp"

namespace mcslam {

struct StampedPose {
  Timestamp t = 0;  // nanoseconds
  SE3 T_w_b;
};
using Trajectory = std::vector<StampedPose>;

// TUM: comment lines (#) and blank lines skipped; timestamps parsed exactly to the nanosecond.
// Throws InputError naming the file, line and value on malformed lines or non-unit quaternions.
Trajectory readTumTrajectory(const std::string& path);
Trajectory parseTumTrajectory(const std::string& text, const std::string& source);
void writeTumTrajectory(const std::string& path, const Trajectory& traj);
std::string formatTumTrajectory(const Trajectory& traj);

// KITTI: one 3x4 matrix per line. Times come from `times_path` (one time in seconds per line, as KITTI's
// times.txt) when given, otherwise frame i gets t = i seconds.
Trajectory readKittiTrajectory(const std::string& path, const std::string& times_path = "");
void writeKittiTrajectory(const std::string& path, const Trajectory& traj);

// A times file (KITTI's times.txt): one time in seconds per line, parsed exactly to the nanosecond.
std::vector<Timestamp> readTimesFile(const std::string& path);

// Either format by name ("tum" or "kitti").
Trajectory readTrajectory(const std::string& path, const std::string& format);

// Total distance travelled along the positions, metres.
double pathLength(const Trajectory& traj);

}  // namespace mcslam
