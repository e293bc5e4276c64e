#pragma once
// Generalized P3P: the body pose from three rays of a (multi-)camera rig and their world points
// (paper eq. 5), allocation-free. Works for any rig, the central case (one camera) included.
//
// Method (Lee, Li, Fraundorfer, Pollefeys, "Minimal solutions for pose estimation of a multi-camera
// system", ISRR 2013): the unknowns are the depths l_i along the rays, the constraints that the
// three ray points keep the world triangle's side lengths:
//   |o_i + l_i d_i - o_j - l_j d_j|^2 = |X_i - X_j|^2      (three quadrics in l_1, l_2, l_3).
// Eliminating l_2 and then l_3 by resultants leaves an octic in l_1 (at most 8 solutions; in the
// central case it is even, a quartic in l_1^2). Its real roots come from a bracketing root finder;
// the depths are then polished by Newton's method on the three quadrics, the pose follows from the
// two congruent triangles, and every returned pose is verified against the rays (no garbage near
// degeneracies: a pose that does not put each point on its ray is dropped).
#include <array>

#include "mcslam/calib/rig.hpp"

namespace mcslam {

// A ray of the rig in the body frame: the camera centre and the unit bearing, both in the body frame.
struct BodyRay {
  Vec3 origin = Vec3::Zero();
  Vec3 direction = Vec3::UnitZ();
};

// The ray of a bearing (unit, camera frame) seen by camera `cam` of the rig.
inline BodyRay bodyRay(const Rig& rig, int cam, const Vec3& bearing_c) {
  const SE3& T_b_c = rig.T_b_c(cam);
  return {T_b_c.t, T_b_c.R * bearing_c};
}

// A Plücker line has no camera centre: the origin becomes the line's point closest to the body
// origin, so "in front of the camera" cannot be checked: solve such rays with Cheirality::Any.
inline BodyRay bodyRayFromPlucker(const PluckerRay& line) { return {line.closestPointToOrigin(), line.d}; }

enum class Cheirality {
  InFront,  // every point must lie in front of its camera (positive depth along the bearing)
  Any,      // depths of either sign (lines without a known camera centre)
};

struct GeneralizedP3PSolutions {
  static constexpr int kMaxSolutions = 8;
  std::array<SE3, kMaxSolutions> T_w_b;  // the first `count` are valid
  int count = 0;
};

// All body poses T_w_b with T_b_w * points_w[i] on rays[i] (i = 0, 1, 2). Returns the number of
// solutions (0 when the three world points are (nearly) collinear or coincide, or when no
// verified pose exists). Directions need not be normalized.
int solveGeneralizedP3P(const std::array<BodyRay, 3>& rays, const std::array<Vec3, 3>& points_w,
                        GeneralizedP3PSolutions& solutions, Cheirality cheirality = Cheirality::InFront);

}  // namespace mcslam
