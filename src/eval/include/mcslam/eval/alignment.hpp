#pragma once
// Umeyama alignment of an estimated trajectory onto a reference (evo/core/geometry.py conventions):
// the similarity (R, t, s) minimising sum |ref_i - (s R est_i + t)|^2 over associated positions.
#include <string>
#include <vector>

#include "mcslam/core/se3.hpp"
#include "mcslam/dataset/trajectory.hpp"

namespace mcslam {

enum class AlignMode { None, SE3, Sim3 };

// "none", "se3", "sim3" <-> AlignMode; parseAlignMode throws InputError on anything else.
AlignMode parseAlignMode(const std::string& name);
const char* alignModeName(AlignMode mode);

// p -> s * R * p + t.
struct Similarity {
  Mat3 R = Mat3::Identity();
  Vec3 t = Vec3::Zero();
  double s = 1.0;

  Vec3 operator*(const Vec3& p) const { return s * (R * p) + t; }
  // A pose of the aligned trajectory: rotated by R, position mapped as a point.
  SE3 apply(const SE3& T) const { return {R * T.R, (*this) * T.t}; }
};

// Least-squares similarity taking `from` onto `to` (same length). with_scale = false fixes s = 1.
// Throws InputError when the points do not fix a rotation (fewer than two independent directions:
// a single point or a straight line), as evo does.
Similarity umeyamaAlignment(const std::vector<Vec3>& from, const std::vector<Vec3>& to, bool with_scale);

Trajectory transformTrajectory(const Trajectory& traj, const Similarity& S);

std::vector<Vec3> positionsOf(const Trajectory& traj);

}  // namespace mcslam
