#pragma once
// Absolute pose of the rig in RANSAC: generalized P3P hypotheses from three random correspondences
// (from any cameras), scored by the reprojection error in pixels through each observation's own
// camera model and extrinsic. Fixed capacity, seeded, allocation-free after construction.
//
// Scoring is MSAC (truncated squared whitened error, which ranks hypotheses with equal inlier
// counts by accuracy) with an exact early exit once a hypothesis can no longer beat the best one.
// The number of samples adapts to the best inlier ratio (confidence), capped by max_iterations.
// The motion-model prediction, when given, is scored first as one more hypothesis. The winner is
// refined on its inliers (PoseRefiner) and the inliers are then re-classified at the refined pose.
// The prediction is also refined over every correspondence and replaces the winner when it keeps more
// inliers: with mostly far points, a sample can give a pose off along a direction they barely
// constrain that still keeps most of them, and the adaptive stop takes it.
#include <cstdint>
#include <span>
#include <vector>

#include "mcslam/geometry/absolute_pose.hpp"
#include "mcslam/geometry/pose_refinement.hpp"
#include "mcslam/geometry/ransac.hpp"

namespace mcslam {

struct AbsolutePoseRansacOptions {
  int max_iterations = 500;       // cap on the number of minimal samples
  double confidence = 0.999;      // of having drawn one all-inlier sample
  double chi2_threshold = 5.991;  // inlier when (error / sigma)^2 below: chi-square, 2 dof, 95%
  int min_inliers = 6;            // fewer: no consensus
  bool refine = true;             // refine the winner on its inliers
  uint64_t seed = 1;              // of the sampler; the sequence continues across calls (see reseed)
};

enum class AbsolutePoseStatus : uint8_t {
  Ok = 0,
  TooFewCorrespondences,  // fewer than 3, or than min_inliers
  OverCapacity,           // more correspondences than the capacity given at construction
  NoConsensus,            // no hypothesis reached min_inliers
};

const char* absolutePoseStatusName(AbsolutePoseStatus s);

struct AbsolutePoseRansacResult {
  AbsolutePoseStatus status = AbsolutePoseStatus::TooFewCorrespondences;
  SE3 T_w_b;
  int num_inliers = 0;
  int iterations = 0;            // minimal samples drawn
  bool from_prediction = false;  // the winning hypothesis was the motion-model prediction
  // One byte per correspondence, 1 = inlier at T_w_b. Points into the estimator: valid until its next call.
  std::span<const uint8_t> inlier_mask;
  bool ok() const { return status == AbsolutePoseStatus::Ok; }
};

class AbsolutePoseRansac {
 public:
  // capacity: the most correspondences one call may pass (buffers are allocated here, once).
  AbsolutePoseRansac(const Rig& rig, int capacity, const AbsolutePoseRansacOptions& options = {});

  // predicted_T_w_b: the motion model's pose, scored as an extra hypothesis (optional).
  AbsolutePoseRansacResult estimate(std::span<const PoseObservation> observations,
                                    const SE3* predicted_T_w_b = nullptr);

  void reseed(uint64_t seed) { random_.seed(seed); }
  const AbsolutePoseRansacOptions& options() const { return options_; }
  int capacity() const { return static_cast<int>(inliers_.size()); }
  void setExtrinsic(int cam, const SE3& T_b_c) {
    rig_.setExtrinsic(cam, T_b_c);
    refiner_.setExtrinsic(cam, T_b_c);
  }

 private:
  // MSAC cost of a hypothesis; stops early (returning a value >= bail_out) once it exceeds bail_out.
  double score(std::span<const PoseObservation> obs, const SE3& T_w_b, double bail_out);
  int classify(std::span<const PoseObservation> obs, const SE3& T_w_b);

  RigProjector rig_;
  AbsolutePoseRansacOptions options_;
  PoseRefiner refiner_;
  RansacRandom random_;
  std::vector<SE3> T_c_w_;  // per camera, for the hypothesis being scored
  std::vector<uint8_t> inliers_;
};

}  // namespace mcslam
