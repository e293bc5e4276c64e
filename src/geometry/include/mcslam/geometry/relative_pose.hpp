#pragma once
// Relative pose between two rig frames, for map initialization (paper IV-B, eq. 4). In fixed memory: a
// RelativePoseEstimator sizes its buffers at construction, so that a rig that loses tracking after the warm-up can
// start a new map without allocating.
//
//  - Generalized (a rig of cameras with distinct centres): the linear 17-point solver (Li, Hartley, Kim 2008) in
//    RANSAC, re-solved on all its inliers; plus, when matches stay within cameras, a rotation-first hypothesis
//    (5-point in the best-covered camera, then the scale most matches agree with), which is where the 17-point
//    solver is weakest. The best refined hypothesis wins. The translation is METRIC. An axial rig (all camera
//    centres on one line, e.g. a stereo pair) with matches only ACROSS its cameras is degenerate for the linear
//    solver (a family of false essential matrices): no pose, the status says so. Within cameras it is not.
//  - Central (one camera): the 5-point solver (Stewenius' form of Nister's problem) in RANSAC; the translation has
//    UNIT NORM (its scale is not observable) and the pose is that of the camera.
// Both are then refined by Levenberg-Marquardt on the generalized epipolar error (eq. 4) divided
// by its first-order standard deviation (a Sampson error, in radians), Huber loss, and inliers
// are re-selected (including: the point triangulates in front of both cameras).
//
// Degenerate motion is reported instead of a wrong initialization: the information matrix of the
// refined pose, with the bearing noise given in the options, yields the standard deviation of the
// metric scale (generalized: zero rotation with a non-overlapping rig leaves it unobservable) and
// of the translation direction (central: too little parallax leaves it unobservable). The caller
// then waits for better frames.
#include <cmath>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "mcslam/calib/rig.hpp"

namespace mcslam {

// A feature matched between frame 1 and frame 2 (possibly seen by different cameras of the rig).
struct RelativeCorrespondence {
  int camera1 = 0;
  Vec3 bearing1 = Vec3::UnitZ();  // unit bearing in camera1's frame, frame 1
  int camera2 = 0;
  Vec3 bearing2 = Vec3::UnitZ();  // unit bearing in camera2's frame, frame 2
};

struct RelativePoseOptions {
  // Standard deviation of a bearing (about pixel sigma / focal length; 1 px at f = 500 here). It sets
  // the inlier threshold and the noise of the observability check.
  double bearing_sigma_rad = 0.002;
  double inlier_sigmas = 3.0;  // inlier when the (Sampson) angle error is below this many sigmas
  int max_iterations = 2000;   // RANSAC samples cap (17 points per sample in the generalized case)
  double confidence = 0.99;
  uint64_t seed = 1;  // RANSAC sampler seed (deterministic)
  int min_inliers = 30;
  double max_relative_scale_sigma = 0.03;  // generalized: sigma(|t|) / |t| above this -> ScaleUnobservable
  double max_direction_sigma_rad = 0.05;   // sigma of the translation direction above this -> DirectionUnobservable
  double min_median_parallax_rad = 0.017;  // median rotation-compensated ray angle below this -> LowParallax (1 deg)
};

enum class RelativePoseStatus : uint8_t {
  Ok = 0,
  TooFewCorrespondences,
  NoConsensus,            // RANSAC found no model with min_inliers
  ScaleUnobservable,      // generalized only: metric scale not determined (e.g. no rotation, no overlap)
  DirectionUnobservable,  // translation direction not determined (e.g. pure rotation)
  LowParallax,            // observable, but the rays are too close to parallel to triangulate well
};

const char* relativePoseStatusName(RelativePoseStatus s);

struct RelativePoseResult {
  RelativePoseStatus status = RelativePoseStatus::TooFewCorrespondences;
  // Frame 2 -> frame 1 (p_1 = T_1_2 * p_2). Generalized: body frames, metric translation.
  // Central: camera frames, |t| = 1.
  SE3 T_1_2;
  bool metric = false;
  std::vector<uint8_t> inlier_mask;  // one per correspondence (up to the estimator's capacity)
  int num_inliers = 0;
  int ransac_iterations = 0;
  double relative_scale_sigma = INFINITY;  // sigma(|t|) / |t| (generalized), infinite for central
  double direction_sigma_rad = INFINITY;   // largest sigma of the translation direction
  double median_parallax_rad = 0;          // median angle between matched rays once the rotation is removed
  bool ok() const { return status == RelativePoseStatus::Ok; }
};

// Owns every buffer of the estimation, sized for `max_correspondences` matches of a rig of up to `max_cameras`
// cameras: after construction it allocates nothing. Matches beyond the capacity are left out.
class RelativePoseEstimator {
 public:
  RelativePoseEstimator(int max_correspondences, int max_cameras);
  ~RelativePoseEstimator();
  RelativePoseEstimator(RelativePoseEstimator&&) noexcept;
  RelativePoseEstimator& operator=(RelativePoseEstimator&&) noexcept;

  // Generalized relative pose of the rig between two frames (metric). A rig of one camera has no metric scale:
  // ScaleUnobservable (use central()). The result stays valid until the next call.
  const RelativePoseResult& generalized(const Rig& rig, std::span<const RelativeCorrespondence> matches,
                                        const RelativePoseOptions& options = {});
  // Central relative pose of one camera between two frames (camera indices are ignored; bearings in the camera
  // frame). Unit translation.
  const RelativePoseResult& central(std::span<const RelativeCorrespondence> matches,
                                    const RelativePoseOptions& options = {});

  struct Workspace;  // relative_pose.cpp

 private:
  std::unique_ptr<Workspace> ws_;
};

// One-off estimations (tests, tools): an estimator sized for these matches.
RelativePoseResult estimateGeneralizedRelativePose(const Rig& rig, std::span<const RelativeCorrespondence> matches,
                                                   const RelativePoseOptions& options = {});
RelativePoseResult estimateCentralRelativePose(std::span<const RelativeCorrespondence> matches,
                                               const RelativePoseOptions& options = {});

}  // namespace mcslam
