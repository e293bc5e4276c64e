#pragma once
// The algebraic solvers of the relative pose, in fixed memory: a lost rig that starts a new map runs them after the
// warm-up, when nothing may allocate. Convention of the whole relative pose: frame 2 -> frame 1, p_1 = R p_2 + t,
// so a match's bearings satisfy d1' E d2 = 0 with E = [t]x R.
#include <array>
#include <span>

#include "mcslam/geometry/relative_pose_refinement.hpp"

namespace mcslam::relative_pose_detail {

// The essential matrices (unit norm, at most 10) in the span of four 3x3 matrices: the ten cubic trace and
// determinant constraints on E = x B0 + y B1 + z B2 + B3, solved with the action matrix of x (Stewenius' Groebner
// basis form). Returns how many real solutions were written.
int essentialsInSpan(const std::array<Mat3, 4>& basis, std::array<Mat3, 10>& E);

// Essential matrices of five matches of unit bearings (Nister's problem): those in the null space of the five
// epipolar constraints. Returns how many real solutions were written (at most 10).
int fivePointEssential(const std::array<Vec3, 5>& d1, const std::array<Vec3, 5>& d2, std::array<Mat3, 10>& E);

// The two rotations an essential matrix allows and its translation direction (unit; its sign is not fixed):
// the poses (R_a, +-t) and (R_b, +-t).
void decomposeEssential(const Mat3& E, Mat3& R_a, Mat3& R_b, Vec3& t);

// The linear generalized epipolar solver (Li, Hartley, Kim 2008) over the rays with mask != 0 (at least 17):
// the generalized epipolar constraint is linear in (E, R); R is eliminated (its least-squares value for each E,
// which also removes the solution E = 0, R = I that every match within one camera satisfies), E is the null
// vector of what remains, and the metric length of t is the least-squares one along E's direction for each of
// E's two rotations. Writes the two poses (one per rotation) and returns false when the system is degenerate.
bool linearGeneralizedPose(std::span<const RayPair> rays, std::span<const uint8_t> mask, std::array<SE3, 2>& poses);

}  // namespace mcslam::relative_pose_detail
