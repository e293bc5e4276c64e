#pragma once
// The parts of the relative pose that are ours (relative_pose.cpp uses them; public for the tests):
// refinement, inlier selection and observability on matched rays, with the generalized epipolar
// constraint (paper eq. 4). In fixed memory: the caller owns every buffer.
#include <span>

#include "mcslam/geometry/relative_pose.hpp"

namespace mcslam::relative_pose_detail {

// A match as two rays, each in its own frame (body frames, or camera frames in the central case):
// camera centre c and unit direction d.
struct RayPair {
  Vec3 c1, d1, c2, d2;
};

// Generalized epipolar error of a match under T_1_2 = (R, t), divided by its first-order standard
// deviation per unit bearing noise (a Sampson error, radians). With J: its derivative with respect
// to [dt; phi] for t + dt, R * exp(phi) with the normalization held fixed; with J_full: the whole derivative, the
// normalization's included (away from the solution the held one is not a descent direction).
double sampsonError(const RayPair& m, const SE3& T_1_2, Eigen::Matrix<double, 1, 6>* J = nullptr,
                    Eigen::Matrix<double, 1, 6>* J_full = nullptr);

// Levenberg-Marquardt with Huber loss over the matches with mask != 0. fixed_scale: |t| keeps its
// starting value (central poses, and the first stage of generalized ones: where the scale is weak
// a free |t| can slide toward the trivial solution t = 0, R = I that every locally central match
// satisfies).
SE3 refineRelativePose(std::span<const RayPair> matches, std::span<const uint8_t> mask, const SE3& T_1_2,
                       bool fixed_scale, const RelativePoseOptions& options);

// Whether the match is within the angle threshold and its point triangulates in front of both cameras.
bool isInlier(const RayPair& match, const SE3& T_1_2, double max_angle_rad);
// Marks the inliers (mask: one per match) and counts them.
int selectInliers(std::span<const RayPair> matches, const SE3& T_1_2, double max_angle_rad, std::span<uint8_t> mask);
int countInliers(std::span<const RayPair> matches, const SE3& T_1_2, double max_angle_rad);

struct Observability {
  double relative_scale_sigma = INFINITY;
  double direction_sigma_rad = INFINITY;
  double median_parallax_rad = 0;
};

// Uncertainty of the translation (metric scale and direction) from the information matrix of the
// inliers at T_1_2, with bearing noise sigma; and the median rotation-compensated parallax (scratch: one per match).
Observability analyzeObservability(std::span<const RayPair> matches, std::span<const uint8_t> mask, const SE3& T_1_2,
                                   bool central, double bearing_sigma_rad, std::span<double> scratch);

}  // namespace mcslam::relative_pose_detail
