#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "mcslam/geometry/pose_refinement.hpp"
#include "pose_scenes.hpp"

using namespace mcslam;
using namespace mcslam::test;

// The analytic Jacobian (full camera model, extrinsic, right perturbation of T_w_b) against
// central differences, on the ring of pinholes with radtan and fisheyes.
TEST(PoseRefinement, ResidualJacobianMatchesNumeric) {
  const Rig rig = ringRig();
  const RigProjector projector(rig);
  SceneRandom r(2);
  const PoseScene scene = makePoseScene(rig, 60, 0.0, 0.0, 1.0, r);
  const SE3 T_w_b = scene.T_w_b;
  for (const PoseObservation& o : scene.observations) {
    Vec2 res;
    Mat26 J;
    ASSERT_TRUE(projector.residual(T_w_b.inverse(), o, res, &J));
    for (int k = 0; k < 6; ++k) {
      const double h = 1e-6;
      Vec6 d = Vec6::Zero();
      d[k] = h;
      Vec2 rp, rm;
      ASSERT_TRUE(projector.residual((T_w_b * SE3::exp(d)).inverse(), o, rp));
      ASSERT_TRUE(projector.residual((T_w_b * SE3::exp(-d)).inverse(), o, rm));
      const Vec2 numeric = (rp - rm) / (2 * h);
      EXPECT_LT((numeric - J.col(k)).norm(), 1e-4 * std::max(1.0, numeric.norm())) << "column " << k;
    }
  }
}

// From a start 5 degrees and 30 cm off, with 1 px noise and 20% gross outliers, on every rig shape:
// the pose comes back to what the noise allows, the outliers are all rejected, and the cost
// matches the noise (mean chi-square about 2 for 2 dof).
TEST(PoseRefinement, ConvergesFromPerturbedStartAndRejectsOutliers) {
  for (const NamedRig& shape : allRigShapes()) {
    SceneRandom r(8);
    PoseRefiner refiner(shape.rig, 400);
    for (int trial = 0; trial < 5; ++trial) {
      const PoseScene scene = makePoseScene(shape.rig, 300, 0.2, 1.0, 1.0, r);
      const SE3 start =
          scene.T_w_b * SE3::exp((Vec6() << 0.3 * r.unitVector(), (5.0 * M_PI / 180) * r.unitVector()).finished());
      const PoseRefinementResult res = refiner.refine(scene.observations, start);
      ASSERT_TRUE(res.success) << shape.name;
      EXPECT_LT(rotationErrorDeg(res.T_w_b, scene.T_w_b), 0.1) << shape.name;
      EXPECT_LT(translationError(res.T_w_b, scene.T_w_b), 0.02) << shape.name;
      int outliers_kept = 0, inliers_lost = 0;
      for (size_t i = 0; i < scene.observations.size(); ++i) {
        outliers_kept += (!scene.is_inlier[i] && res.inlier_mask[i]) ? 1 : 0;
        inliers_lost += (scene.is_inlier[i] && !res.inlier_mask[i]) ? 1 : 0;
      }
      EXPECT_EQ(outliers_kept, 0) << shape.name;
      EXPECT_LE(inliers_lost, 24) << shape.name;  // the 5% chi-square tail of 240 inliers, with margin
      EXPECT_GT(res.mean_chi2, 1.4) << shape.name;
      EXPECT_LT(res.mean_chi2, 2.3) << shape.name;
      // The information is positive definite: every direction of the pose is constrained.
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<Mat6>(res.information).eigenvalues()[0], 0.0) << shape.name;
    }
  }
}

// Per-observation sigma: keypoints of coarse pyramid levels (sigma 4 px, noise 4 px) stay inliers,
// while the same noise with a claimed sigma of 1 px is rejected.
TEST(PoseRefinement, UsesEachObservationsSigma) {
  const Rig rig = stereoRig();
  SceneRandom r(4);
  PoseScene scene = makePoseScene(rig, 200, 0.0, 1.0, 1.0, r);
  for (size_t i = 0; i < scene.observations.size(); i += 2) {
    PoseObservation& o = scene.observations[i];
    PoseObservation noisy;
    ASSERT_TRUE(observe(rig, o.camera, scene.T_w_b, o.point_w, 4.0, 4.0, r, noisy));
    o = noisy;
  }
  PoseRefiner refiner(rig, 200);
  const PoseRefinementResult right = refiner.refine(scene.observations, scene.T_w_b);
  ASSERT_TRUE(right.success);
  EXPECT_GE(right.num_inliers, 180);
  EXPECT_LT(rotationErrorDeg(right.T_w_b, scene.T_w_b), 0.1);

  for (PoseObservation& o : scene.observations) o.sigma_px = 1.0;
  const PoseRefinementResult wrong = refiner.refine(scene.observations, scene.T_w_b);
  EXPECT_LT(wrong.num_inliers, 170);  // many of the 4 px points fail a 1 px test
}

TEST(PoseRefinement, ReportsFailureInsteadOfThrowing) {
  const Rig rig = monoRig();
  SceneRandom r(6);
  const PoseScene scene = makePoseScene(rig, 50, 0.0, 0.5, 1.0, r);
  PoseRefiner small(rig, 10);
  EXPECT_FALSE(small.refine(scene.observations, scene.T_w_b).success);  // over capacity
  PoseRefiner refiner(rig, 50);
  std::vector<uint8_t> wrong_size(3, 1);
  EXPECT_FALSE(refiner.refine(scene.observations, scene.T_w_b, wrong_size).success);
  // A start far behind the scene: nothing projects, no consensus, no crash.
  const SE3 lost = scene.T_w_b * SE3(so3Exp(Vec3(0, M_PI, 0)), Vec3::Zero());
  EXPECT_FALSE(refiner.refine(scene.observations, lost).success);
  // A camera index outside the rig is an outlier, not a crash.
  std::vector<PoseObservation> obs = scene.observations;
  obs[0].camera = 7;
  const PoseRefinementResult res = refiner.refine(obs, scene.T_w_b);
  EXPECT_TRUE(res.success);
  EXPECT_EQ(res.inlier_mask[0], 0);
}
