// The solver on single synthetic windows: convergence to ground truth, outliers, gauge,
// robustness to unconstrained landmarks, symbolic-analysis reuse and the API's status codes.
#include <gtest/gtest.h>

#include <set>
#include <tuple>

#include "backend_testkit.hpp"
#include "mcslam/core/error.hpp"

using namespace mcslam;
using namespace mcslam::backend;
using namespace mcslam::backend::testkit;

namespace {

WindowCapacity smallCapacity() { return {12, 2048, 32768}; }

double translationError(const SE3& a, const SE3& b) { return (a.t - b.t).norm(); }
double rotationErrorDeg(const SE3& a, const SE3& b) { return rotationAngle(a.R, b.R) * 180.0 / M_PI; }

}  // namespace

TEST(SlidingWindowSolver, NoisyWindowConvergesToGroundTruth) {
  SceneOptions so;
  so.landmarks_per_keyframe = 60;
  so.pixel_noise = 0.5;
  const Scene scene = makeScene(isecRig(), so);
  const WindowGuess guess = perturbedGuess(scene, 0.05, 0.02, 0.2, 3);
  SlidingWindowSolver solver(scene.rig, smallCapacity());
  const int landmarks = fillSolver(solver, scene, guess);
  ASSERT_GT(landmarks, 400);

  const SolveSummary s = solver.solve(50);
  EXPECT_TRUE(s.converged);
  EXPECT_FALSE(s.failed);
  EXPECT_EQ(s.landmarks_used, landmarks);
  EXPECT_LT(s.final_cost, 1e-2 * s.initial_cost);
  // At the minimum the cost is the noise: 0.5 * E|r|^2 = 0.5 * 2 * (0.5)^2 per observation.
  EXPECT_LT(s.final_cost, 1.2 * 0.25 * s.residuals_used);
  EXPECT_GT(s.final_cost, 0.6 * 0.25 * s.residuals_used);

  double worst_t = 0, worst_r = 0;
  for (size_t k = 0; k < scene.T_w_b.size(); ++k) {
    SE3 T;
    ASSERT_TRUE(solver.keyframePose(k, T));
    worst_t = std::max(worst_t, translationError(T, scene.T_w_b[k]));
    worst_r = std::max(worst_r, rotationErrorDeg(T, scene.T_w_b[k]));
  }
  EXPECT_LT(worst_t, 0.005);  // from 5 cm
  EXPECT_LT(worst_r, 0.05);   // from ~1 degree per axis
  std::vector<double> point_errors;
  for (size_t l = 0; l < scene.points.size(); ++l) {
    Vec3 p;
    if (solver.landmarkPosition(l, p)) point_errors.push_back((p - scene.points[l]).norm());
  }
  std::nth_element(point_errors.begin(), point_errors.begin() + point_errors.size() / 2, point_errors.end());
  // From 0.35 m (0.2 per axis) to what 0.5 px allows at 2-20 m with short tracks.
  EXPECT_LT(point_errors[point_errors.size() / 2], 0.07);
  EXPECT_EQ(solver.cholmodArenaOverflows(), 0u);
}

TEST(SlidingWindowSolver, EquidistantRigConverges) {
  // A two-fisheye rig (TUM-VI style), looking forward with a 10 cm baseline.
  Rig rig;
  const CameraModel fisheye(
      512, 512, 190.97, 190.97, 254.93, 256.89, Distortion::Equidistant,
      {0.0034823894022493434, 0.0007150348452162257, -0.0020532361418706202, 0.00020293673591811182});
  rig.cameras.push_back({"cam0", fisheye, SE3(), 0});
  rig.cameras.push_back({"cam1", fisheye, SE3(so3Exp(Vec3(0, 0.02, 0)), Vec3(0.1, 0, 0)), 1});
  SceneOptions so;
  so.landmarks_per_keyframe = 60;
  so.pixel_noise = 0.0;  // exact measurements: the minimum is the ground truth
  const Scene scene = makeScene(rig, so);
  const WindowGuess guess = perturbedGuess(scene, 0.03, 0.01, 0.1, 4);
  SlidingWindowSolver solver(rig, smallCapacity());
  fillSolver(solver, scene, guess);
  const SolveSummary s = solver.solve(50);
  EXPECT_TRUE(s.converged);
  EXPECT_LT(s.final_cost, 1e-12 * s.initial_cost);
  for (size_t k = 0; k < scene.T_w_b.size(); ++k) {
    SE3 T;
    solver.keyframePose(k, T);
    EXPECT_LT(translationError(T, scene.T_w_b[k]), 1e-7) << k;  // from 3 cm
    EXPECT_LT(rotationErrorDeg(T, scene.T_w_b[k]), 1e-6) << k;
  }
}

TEST(SlidingWindowSolver, ReportsInjectedOutliers) {
  SceneOptions so;
  so.landmarks_per_keyframe = 60;
  so.outlier_fraction = 0.02;
  so.outlier_pixels = 25.0;
  const Scene scene = makeScene(isecRig(), so);
  SlidingWindowSolver solver(scene.rig, smallCapacity());
  fillSolver(solver, scene, perturbedGuess(scene, 0.02, 0.01, 0.1, 5));
  const SolveSummary s = solver.solve(30);
  EXPECT_FALSE(s.failed);

  // Outliers of landmarks seen 4+ times cannot be absorbed by moving the point (with two views
  // a point can swallow much of one bad view); all of those must be found.
  std::set<std::tuple<int64_t, int64_t, int>> injected, detectable, reported;
  for (const SceneObservation& ob : scene.observations) {
    if (!ob.outlier || scene.num_observations[ob.landmark] < 2) continue;
    injected.insert({ob.keyframe, ob.landmark, ob.camera});
    if (scene.num_observations[ob.landmark] >= 4) detectable.insert({ob.keyframe, ob.landmark, ob.camera});
  }
  for (const ObservationKey& k : solver.outliers()) reported.insert({k.keyframe_id, k.landmark_id, k.camera});
  ASSERT_GT(detectable.size(), 50u);
  int found = 0, found_detectable = 0;
  for (const auto& key : injected) found += reported.count(key);
  for (const auto& key : detectable) found_detectable += reported.count(key);
  EXPECT_EQ(found_detectable, static_cast<int>(detectable.size()));
  EXPECT_GE(found, static_cast<int>(0.97 * injected.size()));
  // At most a handful of inliers flagged (chi-square 95% on noise of a quarter sigma).
  EXPECT_LE(reported.size() - found, 5u);
  EXPECT_EQ(s.outliers, static_cast<int>(reported.size()));
  // The robust loss kept the estimate: poses still within a centimetre.
  for (size_t k = 0; k < scene.T_w_b.size(); ++k) {
    SE3 T;
    solver.keyframePose(k, T);
    EXPECT_LT(translationError(T, scene.T_w_b[k]), 0.01) << k;
  }
  // Removing them is what the odometry does; removal while iterating is allowed.
  for (const ObservationKey& k : solver.outliers()) EXPECT_EQ(solver.removeObservation(k), Status::Ok);
  EXPECT_EQ(solver.solve(10).outliers, 0);
}

TEST(SlidingWindowSolver, UnconstrainedLandmarksAreSkippedNotSingular) {
  SceneOptions so;
  so.landmarks_per_keyframe = 40;
  const Scene scene = makeScene(isecRig(), so);
  SlidingWindowSolver solver(scene.rig, smallCapacity());
  const int landmarks = fillSolver(solver, scene, perturbedGuess(scene, 0.02, 0.01, 0.1, 6));

  // One observation only; and a point 100 km away seen by two keyframes (no parallax).
  const Vec3 lonely(0.5, 0.2, 6.0), far(3e3, 1e3, 1e5);
  ASSERT_EQ(solver.addLandmark(900001, lonely), Status::Ok);
  ASSERT_EQ(solver.addObservation(3, 900001, 0, Vec2(100, 100), 1.0), Status::Ok);
  ASSERT_EQ(solver.addLandmark(900002, far), Status::Ok);
  for (int k : {1, 2}) {
    Vec2 uv;
    ASSERT_TRUE(scene.rig.model(0).project(scene.T_w_b[k].inverse() * far, uv));
    ASSERT_EQ(solver.addObservation(k, 900002, 0, uv + Vec2(0.3, -0.2), 1.0), Status::Ok);
  }
  const SolveSummary s = solver.solve(30);
  EXPECT_TRUE(s.converged);
  EXPECT_EQ(s.landmarks_used, landmarks);
  EXPECT_EQ(s.landmarks_skipped, 2);
  Vec3 p;
  solver.landmarkPosition(900001, p);
  EXPECT_EQ(p, lonely);  // held, not moved
  solver.landmarkPosition(900002, p);
  EXPECT_EQ(p, far);
  for (size_t k = 0; k < scene.T_w_b.size(); ++k) {
    SE3 T;
    solver.keyframePose(k, T);
    EXPECT_TRUE(T.t.allFinite());
    EXPECT_LT(translationError(T, scene.T_w_b[k]), 0.01) << k;
  }
}

TEST(SlidingWindowSolver, GaugeHoldsOldestAndKeyframesFixedById) {
  SceneOptions so;
  so.landmarks_per_keyframe = 40;
  const Scene scene = makeScene(isecRig(), so);
  const WindowGuess guess = perturbedGuess(scene, 0.03, 0.01, 0.1, 7);
  SolverOptions options;
  options.gauge_fixed_oldest = 2;  // as for a monocular rig
  SlidingWindowSolver solver(scene.rig, smallCapacity(), options);
  fillSolver(solver, scene, guess);
  ASSERT_EQ(solver.setKeyframeFixed(6, true), Status::Ok);
  EXPECT_EQ(solver.setKeyframeFixed(77, true), Status::UnknownKeyframe);
  const SolveSummary s = solver.solve(20);
  EXPECT_FALSE(s.failed);
  for (int k : {0, 1, 6}) {
    SE3 T;
    solver.keyframePose(k, T);
    EXPECT_EQ(T.t, guess.T_w_b[k].t) << k;
    EXPECT_EQ(T.R, guess.T_w_b[k].R) << k;
  }
  SE3 T;
  solver.keyframePose(3, T);
  EXPECT_GT((T.t - guess.T_w_b[3].t).norm(), 1e-3);  // the free ones moved
}

// The odometry holds a remembered scale by fixing a second keyframe at run time (setGaugeFixedOldest), and lets
// it go with 1 again.
TEST(SlidingWindowSolver, GaugeOfTheOldestKeyframesChangesAtRunTime) {
  SceneOptions so;
  so.landmarks_per_keyframe = 40;
  const Scene scene = makeScene(isecRig(), so);
  const WindowGuess guess = perturbedGuess(scene, 0.03, 0.01, 0.1, 7);
  SlidingWindowSolver solver(scene.rig, smallCapacity());  // default: the oldest keyframe alone
  fillSolver(solver, scene, guess);
  EXPECT_EQ(solver.setGaugeFixedOldest(-1), Status::InvalidValue);
  ASSERT_EQ(solver.setGaugeFixedOldest(2), Status::Ok);
  EXPECT_FALSE(solver.solve(20).failed);
  SE3 T;
  for (int k : {0, 1}) {
    solver.keyframePose(k, T);
    EXPECT_EQ(T.t, guess.T_w_b[k].t) << k;
  }
  ASSERT_EQ(solver.setGaugeFixedOldest(1), Status::Ok);
  EXPECT_FALSE(solver.solve(20).failed);
  solver.keyframePose(0, T);
  EXPECT_EQ(T.t, guess.T_w_b[0].t);
  solver.keyframePose(1, T);
  EXPECT_GT((T.t - guess.T_w_b[1].t).norm(), 1e-3);  // free again: it moves
}

TEST(SlidingWindowSolver, HoldingTheWindowScaleKeepsTheSummedDistancesOfItsKeyframes) {
  // The guess 10% larger than the scene about the oldest keyframe: the 5-camera rig's reprojections want the
  // scene's unit back, the hold keeps the guess's (the summed distances from the oldest keyframe of those
  // between it and the newest), and only the oldest keyframe is fixed.
  SceneOptions so;
  so.landmarks_per_keyframe = 40;
  const Scene scene = makeScene(isecRig(), so);
  WindowGuess guess = perturbedGuess(scene, 0.03, 0.01, 0.1, 7);
  const Vec3 anchor = guess.T_w_b[0].t;
  for (SE3& T : guess.T_w_b) T.t = anchor + 1.1 * (T.t - anchor);
  for (Vec3& p : guess.points) p = anchor + 1.1 * (p - anchor);
  const int n = static_cast<int>(guess.T_w_b.size());
  ASSERT_GE(n, 4);
  auto held = [&](auto pose) {
    double d = 0;
    for (int k = 1; k < n - 1; ++k) d += (pose(k).t - anchor).norm();
    return d;
  };
  const double before = held([&](int k) { return guess.T_w_b[k]; });
  for (const bool hold : {false, true}) {
    SlidingWindowSolver solver(scene.rig, smallCapacity());
    fillSolver(solver, scene, guess);
    ASSERT_EQ(solver.setGaugeFixedOldest(1), Status::Ok);
    solver.setHoldWindowScale(hold);
    const SolveSummary s = solver.solve(30);
    ASSERT_FALSE(s.failed);
    EXPECT_LT(s.final_cost, s.initial_cost);
    auto pose = [&](int k) {
      SE3 T;
      solver.keyframePose(k, T);
      return T;
    };
    EXPECT_EQ(pose(0).t, anchor);
    EXPECT_GT((pose(1).t - guess.T_w_b[1].t).norm(), 1e-3);  // free: it moves
    const double ratio = held(pose) / before;
    if (hold) {
      EXPECT_NEAR(ratio, 1.0, 1e-3);
    } else {
      EXPECT_NEAR(ratio, 1.0 / 1.1, 0.01);  // the rig's overlap finds the scene's unit
    }
  }
}

TEST(SlidingWindowSolver, SymbolicAnalysisRedoneOnlyWhenStructureChanges) {
  SceneOptions so;
  so.landmarks_per_keyframe = 40;
  so.num_keyframes = 11;
  const Scene scene = makeScene(isecRig(), so);
  const WindowGuess guess = perturbedGuess(scene, 0.02, 0.01, 0.1, 8);
  SlidingWindowSolver solver(scene.rig, smallCapacity());
  // All but the last keyframe first.
  for (int k = 0; k < 10; ++k) solver.addKeyframe(k, guess.T_w_b[k]);
  for (size_t l = 0; l < scene.points.size(); ++l) solver.addLandmark(l, guess.points[l]);
  for (const SceneObservation& ob : scene.observations) {
    if (ob.keyframe < 10) solver.addObservation(ob.keyframe, ob.landmark, ob.camera, ob.uv, ob.sigma);
  }
  EXPECT_EQ(solver.solve(10).symbolic_analyses, 1);
  EXPECT_EQ(solver.solve(10).symbolic_analyses, 0);  // same structure: analysis reused
  solver.addKeyframe(10, guess.T_w_b[10]);
  for (int idx : scene.observations_of_keyframe[10]) {
    const SceneObservation& ob = scene.observations[idx];
    solver.addObservation(10, ob.landmark, ob.camera, ob.uv, ob.sigma);
  }
  EXPECT_EQ(solver.solve(10).symbolic_analyses, 1);  // one more block: analysed again
  EXPECT_EQ(solver.solve(10).symbolic_analyses, 0);
}

TEST(SlidingWindowSolver, StatusCodes) {
  const Rig rig = isecRig();
  SlidingWindowSolver solver(rig, {2, 2, 3});
  EXPECT_EQ(solver.solve(5).failed, true);  // empty
  EXPECT_EQ(solver.marginalizeOldest(), Status::EmptyWindow);
  EXPECT_EQ(solver.addKeyframe(1, SE3()), Status::Ok);
  EXPECT_EQ(solver.addKeyframe(1, SE3()), Status::DuplicateId);
  EXPECT_EQ(solver.addKeyframe(2, SE3(Mat3::Identity(), Vec3(NAN, 0, 0))), Status::InvalidValue);
  EXPECT_EQ(solver.addKeyframe(2, SE3()), Status::Ok);
  EXPECT_TRUE(solver.isFull());
  EXPECT_EQ(solver.addKeyframe(3, SE3()), Status::CapacityExceeded);
  EXPECT_EQ(solver.addLandmark(10, Vec3(0, 0, 5)), Status::Ok);
  EXPECT_EQ(solver.addLandmark(10, Vec3(0, 0, 5)), Status::DuplicateId);
  EXPECT_EQ(solver.addLandmark(11, Vec3(0, 0, 6)), Status::Ok);
  EXPECT_EQ(solver.addLandmark(12, Vec3(0, 0, 6)), Status::CapacityExceeded);
  EXPECT_EQ(solver.addObservation(9, 10, 0, Vec2(1, 1), 1.0), Status::UnknownKeyframe);
  EXPECT_EQ(solver.addObservation(1, 99, 0, Vec2(1, 1), 1.0), Status::UnknownLandmark);
  EXPECT_EQ(solver.addObservation(1, 10, 5, Vec2(1, 1), 1.0), Status::InvalidCamera);
  EXPECT_EQ(solver.addObservation(1, 10, 0, Vec2(1, 1), 0.0), Status::InvalidValue);
  EXPECT_EQ(solver.addObservation(1, 10, 0, Vec2(1, 1), 1.0), Status::Ok);
  EXPECT_EQ(solver.addObservation(1, 10, 0, Vec2(2, 2), 1.0), Status::DuplicateId);
  EXPECT_EQ(solver.addObservation(2, 10, 0, Vec2(1, 1), 1.0), Status::Ok);
  EXPECT_EQ(solver.addObservation(1, 11, 0, Vec2(1, 1), 1.0), Status::Ok);
  EXPECT_EQ(solver.addObservation(2, 11, 0, Vec2(1, 1), 1.0), Status::CapacityExceeded);
  EXPECT_EQ(solver.removeObservation({2, 11, 0}), Status::UnknownObservation);
  EXPECT_EQ(solver.removeObservation({1, 11, 0}), Status::Ok);
  EXPECT_EQ(solver.numObservations(), 2);
  EXPECT_EQ(solver.removeLandmark(10), Status::Ok);
  EXPECT_EQ(solver.numObservations(), 0);
  EXPECT_EQ(solver.removeLandmark(10), Status::UnknownLandmark);
  // Slots are reused after removal.
  EXPECT_EQ(solver.addLandmark(12, Vec3(0, 0, 6)), Status::Ok);
  EXPECT_EQ(*solver.oldestKeyframe(), 1);
  EXPECT_EQ(solver.marginalizeOldest(), Status::Ok);
  EXPECT_EQ(*solver.oldestKeyframe(), 2);
  EXPECT_EQ(solver.numKeyframes(), 1);
  EXPECT_FALSE(solver.isFull());
}

TEST(SlidingWindowSolver, BadConfigurationThrowsAtConstruction) {
  const Rig rig = isecRig();
  SolverOptions bad_reference;
  bad_reference.reference_camera = 5;
  EXPECT_THROW(SlidingWindowSolver(rig, {}, bad_reference), InputError);
  EXPECT_THROW(SlidingWindowSolver(rig, {0, 10, 10}), InputError);
  SolverOptions bad_sigma;
  bad_sigma.extrinsic_prior.rotation = 0;
  EXPECT_THROW(SlidingWindowSolver(rig, {}, bad_sigma), InputError);
}

TEST(SlidingWindowSolver, AllKeyframesFixedRefinesLandmarksOnly) {
  // No free pose and no extrinsic: no reduced system at all, only the landmark steps.
  SceneOptions so;
  so.landmarks_per_keyframe = 30;
  const Scene scene = makeScene(isecRig(), so);
  WindowGuess guess = perturbedGuess(scene, 0.0, 0.0, 0.2, 9);
  guess.T_w_b = scene.T_w_b;  // true poses
  SolverOptions options;
  options.gauge_fixed_oldest = 10;
  SlidingWindowSolver solver(scene.rig, smallCapacity(), options);
  fillSolver(solver, scene, guess);
  const SolveSummary s = solver.solve(20);
  EXPECT_TRUE(s.converged);
  EXPECT_EQ(s.symbolic_analyses, 0);
  EXPECT_LT(s.final_cost, 0.01 * s.initial_cost);
  SE3 T;
  solver.keyframePose(4, T);
  EXPECT_EQ(T.t, scene.T_w_b[4].t);
}
