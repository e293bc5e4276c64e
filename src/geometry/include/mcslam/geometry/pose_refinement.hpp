#pragma once
// Pose-only robust refinement of the body pose T_w_b over all observations of a rig frame, every
// camera at once, allocation-free after construction.
//
// Levenberg-Marquardt on the reprojection error in pixels through each camera's full model
// (distortion included) and its extrinsic, whitened by each observation's sigma, with analytic
// Jacobians and the pose perturbed on the right (T_w_b * exp(delta), delta = [rho; phi]).
// Outliers are handled the ORB-SLAM way: several rounds; after each round every observation
// (the rejected ones too) is classified by its chi-square error at the current pose, and only the
// inliers take part in the next round. Huber weights in the first rounds, plain least squares in
// the last ones once the outliers are gone.
#include <cstdint>
#include <span>
#include <vector>

#include "mcslam/geometry/absolute_pose.hpp"

namespace mcslam {

struct PoseRefinementOptions {
  int rounds = 4;  // outlier-rejection rounds (ORB-SLAM: 4 x 10 iterations)
  int iterations_per_round = 10;
  int robust_rounds = 2;            // rounds with the Huber loss; the later ones use plain squares
  double chi2_threshold = 5.991;    // inlier when (error / sigma)^2 below: chi-square, 2 dof, 95%
  double huber_threshold = 2.4477;  // whitened error (sigmas) where the Huber loss turns linear: sqrt(5.991)
  // Errors beyond this many sigmas count as a constant, like a point that does not project at all:
  // a gross outlier of a wide-angle lens (hundreds of pixels) then neither dominates the Huber sum
  // nor gains the optimizer anything by being pushed out of the lens's domain.
  double gross_error_sigmas = 100.0;
  int min_inliers = 6;  // fewer: the refinement fails
};

struct PoseRefinementResult {
  bool success = false;
  SE3 T_w_b;
  int num_inliers = 0;
  double cost = 0;       // sum over the inliers of (error / sigma)^2 at T_w_b
  double mean_chi2 = 0;  // cost / num_inliers: near 2 when the sigmas describe the noise
  // Information of the pose, sum of J^T J / sigma^2 over the inliers at T_w_b (right perturbation,
  // [rho; phi]). Its smallest eigenvalue tells how well the weakest direction is constrained.
  Mat6 information = Mat6::Zero();
  int iterations = 0;  // Levenberg-Marquardt steps tried, all rounds
  // One byte per observation, 1 = inlier at T_w_b. Points into the refiner: valid until its next call.
  std::span<const uint8_t> inlier_mask;
};

class PoseRefiner {
 public:
  // capacity: the most observations one call may pass (the buffers are allocated here, once).
  PoseRefiner(const Rig& rig, int capacity, const PoseRefinementOptions& options = {});

  // Refines T_w_b from `initial_T_w_b`. initial_inliers (optional, one byte per observation) chooses
  // the observations of the first round; by default all. More observations than the capacity, or an
  // initial_inliers of the wrong size: success = false and the initial pose is returned.
  PoseRefinementResult refine(std::span<const PoseObservation> observations, const SE3& initial_T_w_b,
                              std::span<const uint8_t> initial_inliers = {});

  const PoseRefinementOptions& options() const { return options_; }
  void setOptions(const PoseRefinementOptions& options) { options_ = options; }
  int capacity() const { return static_cast<int>(inliers_.size()); }
  void setExtrinsic(int cam, const SE3& T_b_c) { rig_.setExtrinsic(cam, T_b_c); }

 private:
  struct Pass {
    double cost = 0;     // robust or plain, over the inliers
    double squares = 0;  // sum of (error / sigma)^2 over the linearized inliers
    Mat6 H = Mat6::Zero();
    Vec6 g = Vec6::Zero();
    int inliers = 0;  // counted when the pass reclassifies
  };
  class Problem;  // the Levenberg-Marquardt problem of one round
  Pass evaluate(std::span<const PoseObservation> obs, const SE3& T_b_w, bool robust, bool reclassify, bool linearize);

  RigProjector rig_;
  PoseRefinementOptions options_;
  std::vector<uint8_t> inliers_;
};

}  // namespace mcslam
