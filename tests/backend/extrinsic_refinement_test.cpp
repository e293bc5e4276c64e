// Online extrinsic refinement on a sliding sequence: a camera whose calibration is off by 2 cm
// and 1 degree is recovered to 5 mm and 0.2 degree; the refined rig is what refinedRig() returns.
// An estimate set from outside (setExtrinsic) unlinks the camera from the marginalization prior and drops its
// calibration prior.
#include <gtest/gtest.h>

#include "backend_testkit.hpp"

using namespace mcslam;
using namespace mcslam::backend;
using namespace mcslam::backend::testkit;

TEST(ExtrinsicRefinement, RecoversTwoCentimetresAndOneDegreeOnASequence) {
  SceneOptions so;
  so.num_keyframes = 40;  // 10 m
  so.landmarks_per_keyframe = 80;
  so.pixel_noise = 0.5;
  so.seed = 41;
  const Rig truth = isecRig();
  const Scene scene = makeScene(truth, so);  // observations made with the true rig
  const int camera = 3;
  const Rig calibrated = perturbExtrinsic(truth, camera, 0.02, 1.0 * M_PI / 180);
  const SE3& T_true = truth.T_b_c(camera);
  ASSERT_NEAR((calibrated.T_b_c(camera).t - T_true.t).norm(), 0.02, 1e-12);
  ASSERT_NEAR(rotationAngle(calibrated.T_b_c(camera).R, T_true.R) * 180 / M_PI, 1.0, 1e-9);

  SolverOptions options;
  options.refine_extrinsics = true;  // the calibration's own prior: 1 cm, 1 degree
  SlidingWindowSolver solver(calibrated, {10, 4096, 65536}, options);
  const SlidingRunResult run = runSliding(solver, scene, {});
  EXPECT_EQ(run.failed_solves, 0);
  EXPECT_EQ(run.refused, 0);

  const SE3& T = solver.extrinsic(camera);
  const double t_err = (T.t - T_true.t).norm();
  const double r_err = rotationAngle(T.R, T_true.R) * 180 / M_PI;
  EXPECT_LT(t_err, 0.005);
  EXPECT_LT(r_err, 0.2);
  RecordProperty("translation_error_mm", std::to_string(t_err * 1e3));
  RecordProperty("rotation_error_deg", std::to_string(r_err));
  // The other cameras were right and stay right; the reference camera never moves.
  for (int c = 1; c < truth.size(); ++c) {
    if (c == camera) continue;
    EXPECT_LT((solver.extrinsic(c).t - truth.T_b_c(c).t).norm(), 0.005) << c;
  }
  EXPECT_EQ(solver.extrinsic(0).t, truth.T_b_c(0).t);
  const Rig refined = solver.refinedRig();
  EXPECT_EQ(refined.T_b_c(camera).t, T.t);
  EXPECT_EQ(refined.model(camera).fx(), truth.model(camera).fx());
}

TEST(ExtrinsicRefinement, WithoutRefinementTheErrorStays) {
  // The same sequence with refinement off: the extrinsic is exactly the calibration's.
  SceneOptions so;
  so.num_keyframes = 14;
  so.landmarks_per_keyframe = 60;
  so.seed = 41;
  const Rig truth = isecRig();
  const Scene scene = makeScene(truth, so);
  const Rig calibrated = perturbExtrinsic(truth, 3, 0.02, 1.0 * M_PI / 180);
  SlidingWindowSolver solver(calibrated, {10, 4096, 65536});
  EXPECT_EQ(runSliding(solver, scene, {}).refused, 0);
  EXPECT_EQ(solver.extrinsic(3).t, calibrated.T_b_c(3).t);
}

TEST(ExtrinsicRefinement, AnEstimateSetFromOutsideIsWhereTheSolveStarts) {
  const Rig truth = isecRig();
  const Rig calibrated = perturbExtrinsic(truth, 3, 0.02, 1.0 * M_PI / 180);
  SolverOptions options;
  options.refine_extrinsics = true;
  SlidingWindowSolver solver(calibrated, {10, 4096, 65536}, options);
  // The reference camera anchors the body frame; bad values and unknown cameras are refused.
  EXPECT_EQ(solver.setExtrinsic(0, truth.T_b_c(0)), Status::InvalidCamera);
  EXPECT_EQ(solver.setExtrinsic(7, truth.T_b_c(3)), Status::InvalidCamera);
  SE3 bad = truth.T_b_c(3);
  bad.t.x() = NAN;
  EXPECT_EQ(solver.setExtrinsic(3, bad), Status::InvalidValue);
  ASSERT_EQ(solver.setExtrinsic(3, truth.T_b_c(3)), Status::Ok);
  EXPECT_LT((solver.extrinsic(3).t - truth.T_b_c(3).t).norm(), 1e-12);
  // The camera's calibration, shown wrong, is no longer a prior (unless the caller keeps it).
  EXPECT_FALSE(solver.hasCalibrationPrior(3));
  EXPECT_TRUE(solver.hasCalibrationPrior(2));
  ASSERT_EQ(solver.setExtrinsic(2, truth.T_b_c(2), true), Status::Ok);
  EXPECT_TRUE(solver.hasCalibrationPrior(2));
  EXPECT_FALSE(solver.hasCalibrationPrior(0));  // the reference camera is not refined at all
  EXPECT_LT(rotationAngle(solver.extrinsic(3).R, truth.T_b_c(3).R), 1e-9);

  // Once the marginalization prior holds information on the camera, a new estimate unlinks it from the prior
  // (the prior was linearized at the old one); the other cameras stay linked.
  SceneOptions so;
  so.num_keyframes = 14;
  so.landmarks_per_keyframe = 60;
  so.seed = 41;
  const Scene scene = makeScene(truth, so);
  SlidingWindowSolver linked(calibrated, {10, 4096, 65536}, options);
  ASSERT_GT(runSliding(linked, scene, {}).marginalizations, 0);
  ASSERT_TRUE(linked.extrinsicInPrior(3));
  ASSERT_TRUE(linked.extrinsicInPrior(2));
  ASSERT_EQ(linked.setExtrinsic(3, truth.T_b_c(3)), Status::Ok);
  EXPECT_FALSE(linked.extrinsicInPrior(3));
  EXPECT_TRUE(linked.extrinsicInPrior(2));
  EXPECT_EQ(linked.priorInformation().middleRows<6>(6 * 2).norm(), 0.0);  // camera 3 is the third free one
  EXPECT_GT(linked.priorInformation().middleRows<6>(6 * 1).norm(), 0.0);
  EXPECT_LT((linked.extrinsic(3).t - truth.T_b_c(3).t).norm(), 1e-12);

  // Without refinement nothing may move an extrinsic.
  SlidingWindowSolver fixed(calibrated, {10, 4096, 65536});
  EXPECT_EQ(fixed.setExtrinsic(3, truth.T_b_c(3)), Status::InvalidCamera);
  EXPECT_EQ(fixed.extrinsic(3).t, calibrated.T_b_c(3).t);
}
