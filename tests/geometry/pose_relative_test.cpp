#include <gtest/gtest.h>

#include <opengv/relative_pose/CentralRelativeAdapter.hpp>
#include <opengv/relative_pose/methods.hpp>

#include "alloc_testing.hpp"
#include "mcslam/core/alloc_counter.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/geometry/relative_pose.hpp"
#include "mcslam/geometry/relative_pose_refinement.hpp"
#include "mcslam/geometry/relative_pose_solvers.hpp"
#include "relative_pose_scenes.hpp"

using namespace mcslam;
using namespace mcslam::test;

namespace {

// Options matching the simulated noise: pixel sigma over the focal length, with 20% for the
// lens distortion that stretches the angle of a pixel toward the image edges.
RelativePoseOptions optionsForNoise(double noise_px) {
  RelativePoseOptions o;
  o.bearing_sigma_rad = 1.2 * noise_px / pinholeRadtan().fx();
  return o;
}

// The matches as rays in the body frames (what the solvers take).
std::vector<relative_pose_detail::RayPair> bodyRays(const Rig& rig, const TwoFrames& f) {
  std::vector<relative_pose_detail::RayPair> rays;
  for (const RelativeCorrespondence& m : f.matches) {
    rays.push_back({rig.T_b_c(m.camera1).t, rig.T_b_c(m.camera1).R * m.bearing1.normalized(), rig.T_b_c(m.camera2).t,
                    rig.T_b_c(m.camera2).R * m.bearing2.normalized()});
  }
  return rays;
}

int maskErrors(const TwoFrames& f, const std::vector<uint8_t>& mask) {
  int wrong = 0;
  for (size_t i = 0; i < mask.size(); ++i) wrong += (mask[i] != 0) != (f.is_inlier[i] != 0) ? 1 : 0;
  return wrong;
}

// Derivative of the Sampson error e / s with respect to parameter k of [dt; phi] (t + dt, R exp(phi)), by central
// differences with step h.
double numericSampsonDerivative(const relative_pose_detail::RayPair& p, const SE3& T, int k, double h) {
  SE3 Tp = T, Tm = T;
  if (k < 3) {
    Tp.t[k] += h;
    Tm.t[k] -= h;
  } else {
    Tp.R = T.R * so3Exp(Vec3::Unit(k - 3) * h);
    Tm.R = T.R * so3Exp(-Vec3::Unit(k - 3) * h);
  }
  return (relative_pose_detail::sampsonError(p, Tp) - relative_pose_detail::sampsonError(p, Tm)) / (2 * h);
}

}  // namespace

TEST(RelativePose, SampsonJacobianMatchesNumeric) {
  const Rig rig = nonOverlappingRig();
  SceneRandom r(3);
  // Noise-free matches at the true pose: the error is zero there, so the derivative of e / s equals
  // de / s, which is what J holds (the normalization s is frozen during a step).
  const TwoFrames f = makeTwoFrames(rig, motion(20, Vec3(0.4, 0.05, 0.6)), 30, 0.0, 0.0, r);
  const SE3 T = f.T_1_2;
  for (const RelativeCorrespondence& m : f.matches) {
    const relative_pose_detail::RayPair p{rig.T_b_c(m.camera1).t, rig.T_b_c(m.camera1).R * m.bearing1,
                                          rig.T_b_c(m.camera2).t, rig.T_b_c(m.camera2).R * m.bearing2};
    Eigen::Matrix<double, 1, 6> J;
    relative_pose_detail::sampsonError(p, T, &J);
    for (int k = 0; k < 6; ++k) {
      const double numeric = numericSampsonDerivative(p, T, k, 1e-7);
      EXPECT_NEAR(numeric, J(k), 1e-5 * std::max(1.0, std::abs(numeric))) << k;
    }
  }
}

// Away from the solution the normalization moves too: the whole derivative (what the refinement steps with) must
// match central differences of e / s at poses that are off, with noisy matches.
TEST(RelativePose, SampsonFullJacobianMatchesNumericAwayFromTheSolution) {
  const Rig rig = nonOverlappingRig();
  SceneRandom r(5);
  const TwoFrames f = makeTwoFrames(rig, motion(25, Vec3(0.5, -0.1, 0.7)), 40, 1.0, 0.0, r);
  const SE3 offsets[] = {SE3(so3Exp(Vec3(0.05, -0.03, 0.02)), Vec3(0.1, 0.05, -0.2)),
                         SE3(so3Exp(Vec3(-0.2, 0.1, 0.15)), Vec3(-0.3, 0.2, 0.1))};
  int checked = 0;
  for (const SE3& offset : offsets) {
    const SE3 T = f.T_1_2 * offset;
    for (const RelativeCorrespondence& m : f.matches) {
      const relative_pose_detail::RayPair p{rig.T_b_c(m.camera1).t, rig.T_b_c(m.camera1).R * m.bearing1.normalized(),
                                            rig.T_b_c(m.camera2).t, rig.T_b_c(m.camera2).R * m.bearing2.normalized()};
      Eigen::Matrix<double, 1, 6> J_held, J;
      relative_pose_detail::sampsonError(p, T, &J_held, &J);
      double largest = 0;
      for (int k = 0; k < 6; ++k) {
        const double numeric = numericSampsonDerivative(p, T, k, 1e-6);
        EXPECT_NEAR(numeric, J(k), 1e-6 * std::max(1.0, std::abs(numeric))) << k;
        largest = std::max(largest, std::abs(J(k) - J_held(k)));
      }
      checked += largest > 1e-3 ? 1 : 0;  // where the normalization's share is not negligible
    }
  }
  EXPECT_GT(checked, 10);  // the test covers what the held derivative misses
}

// Rays through the origin (one camera) take a shorter form of the error that leaves out their zero centres. It
// must agree with the general form, here reached by a centre too small to change any value, and with central
// differences, at poses away from the solution.
TEST(RelativePose, CentralRaysGiveTheGeneralFormsErrorAndDerivatives) {
  const Rig rig = nonOverlappingRig();
  SceneRandom r(7);
  const TwoFrames f = makeTwoFrames(rig, motion(25, Vec3(0.5, -0.1, 0.7)), 40, 1.0, 0.0, r);
  const SE3 T = f.T_1_2 * SE3(so3Exp(Vec3(-0.2, 0.1, 0.15)), Vec3(-0.3, 0.2, 0.1));
  const Vec3 negligible(1e-300, 0, 0);
  ASSERT_GT(f.matches.size(), 20u);
  for (const RelativeCorrespondence& m : f.matches) {
    const Vec3 d1 = m.bearing1.normalized(), d2 = m.bearing2.normalized();
    const relative_pose_detail::RayPair central{Vec3::Zero(), d1, Vec3::Zero(), d2};
    const relative_pose_detail::RayPair general{negligible, d1, negligible, d2};
    Eigen::Matrix<double, 1, 6> J_held_c, J_c, J_held_g, J_g;
    const double e_c = relative_pose_detail::sampsonError(central, T, &J_held_c, &J_c);
    const double e_g = relative_pose_detail::sampsonError(general, T, &J_held_g, &J_g);
    EXPECT_NEAR(e_c, e_g, 1e-15);
    for (int k = 0; k < 6; ++k) {
      EXPECT_NEAR(J_held_c(k), J_held_g(k), 1e-12) << k;
      EXPECT_NEAR(J_c(k), J_g(k), 1e-12) << k;
      const double numeric = numericSampsonDerivative(central, T, k, 1e-6);
      EXPECT_NEAR(numeric, J_c(k), 1e-6 * std::max(1.0, std::abs(numeric))) << k;
    }
  }
}

// Three non-overlapping cameras 0.3 m apart, 30 degrees of rotation and 1 m of translation,
// 0.3 px noise and 20% outliers: metric translation within a few percent, consistent with the
// reported scale uncertainty, and the inlier set right.
// Three non-overlapping cameras 0.3 m apart, 30 degrees of rotation and 1 m of translation,
// 0.3 px noise and 20% outliers, six scenes: metric translation within a few percent, each error
// within 3 reported sigmas, and the inlier set right.
TEST(RelativePose, GeneralizedRecoversMetricMotionOfNonOverlappingRig) {
  const Rig rig = wideNonOverlappingRig();
  double sum_ratio2 = 0;
  for (int seed = 1; seed <= 6; ++seed) {
    SceneRandom r(seed);
    const TwoFrames f = makeTwoFrames(rig, motion(30, Vec3(0.6, 0.05, 0.8)), 300, 0.2, 0.3, r);
    const RelativePoseResult res = estimateGeneralizedRelativePose(rig, f.matches, optionsForNoise(0.3));
    ASSERT_EQ(res.status, RelativePoseStatus::Ok) << relativePoseStatusName(res.status);
    EXPECT_TRUE(res.metric);
    const double scale_error = res.T_1_2.t.norm() / f.T_1_2.t.norm() - 1.0;
    std::printf(
        "non-overlapping scene %d: |t| %.4f m (true %.4f), scale error %+.2f%%, sigma %.2f%%, rotation error %.4f "
        "deg\n",
        seed, res.T_1_2.t.norm(), f.T_1_2.t.norm(), 100 * scale_error, 100 * res.relative_scale_sigma,
        rotationErrorDeg(res.T_1_2, f.T_1_2));
    EXPECT_LT(std::abs(scale_error), 0.05) << seed;
    EXPECT_LT(std::abs(scale_error), 3.0 * res.relative_scale_sigma) << seed;
    EXPECT_LT((res.T_1_2.t - f.T_1_2.t).norm() / f.T_1_2.t.norm(), 0.05) << seed;
    EXPECT_LT(rotationErrorDeg(res.T_1_2, f.T_1_2), 0.1) << seed;
    EXPECT_LE(maskErrors(f, res.inlier_mask), 4) << seed;  // noisy inliers at the 3-sigma threshold
    sum_ratio2 += std::pow(scale_error / res.relative_scale_sigma, 2);
  }
  EXPECT_LT(std::sqrt(sum_ratio2 / 6), 2.0);  // the reported sigma describes the error
}

// The same rig without rotation, or with too little: every match stays in its camera, so the
// metric scale is (nearly) unobservable and this is reported, whatever the solvers returned.
TEST(RelativePose, GeneralizedReportsUnobservableScaleWithoutRotation) {
  const Rig rig = wideNonOverlappingRig();
  SceneRandom r(7);
  for (double yaw : {0.0, 1.0, 5.0}) {
    const TwoFrames f = makeTwoFrames(rig, motion(yaw, Vec3(0.6, 0.05, 0.8)), 300, 0.1, 0.3, r);
    const RelativePoseResult res = estimateGeneralizedRelativePose(rig, f.matches, optionsForNoise(0.3));
    std::printf("yaw %.1f deg: status %s, relative scale sigma %.3g\n", yaw, relativePoseStatusName(res.status),
                res.relative_scale_sigma);
    EXPECT_EQ(res.status, RelativePoseStatus::ScaleUnobservable) << yaw;
    EXPECT_GT(res.relative_scale_sigma, 0.03);
    EXPECT_GE(res.num_inliers, 250);  // the motion itself was found; only its scale is unknown
  }
}

// Overlapping cameras with matches across cameras have metric scale even without rotation.
TEST(RelativePose, GeneralizedCrossCameraMatchesGiveScaleWithoutRotation) {
  const Rig rig = trinocularRig();
  SceneRandom r(9);
  const TwoFrames f = makeTwoFrames(rig, motion(0, Vec3(0.1, 0.0, 0.5)), 300, 0.1, 0.5, r, true);
  const RelativePoseResult res = estimateGeneralizedRelativePose(rig, f.matches, optionsForNoise(0.5));
  ASSERT_EQ(res.status, RelativePoseStatus::Ok) << relativePoseStatusName(res.status);
  EXPECT_LT((res.T_1_2.t - f.T_1_2.t).norm() / f.T_1_2.t.norm(), 0.05);
}

// A stereo pair is an axial rig (its centres on one line): with matches only across its cameras, the linear
// generalized constraint has a family of false essential matrices (Li, Hartley, Kim 2008), and no pose comes out.
// That is reported, never a wrong pose. (The initializer matches within cameras, where the pair is not degenerate.)
TEST(RelativePose, GeneralizedAxialRigAcrossCamerasIsReportedNotGuessed) {
  const Rig rig = stereoRig();
  SceneRandom r(9);
  const TwoFrames f = makeTwoFrames(rig, motion(0, Vec3(0.1, 0.0, 0.5)), 300, 0.1, 0.5, r, true);
  const RelativePoseResult res = estimateGeneralizedRelativePose(rig, f.matches, optionsForNoise(0.5));
  std::printf("stereo across cameras: status %s\n", relativePoseStatusName(res.status));
  EXPECT_NE(res.status, RelativePoseStatus::Ok);
}

// One camera: direction of translation and rotation; unit translation.
TEST(RelativePose, CentralRecoversRotationAndTranslationDirection) {
  const Rig rig = monoRig();
  SceneRandom r(11);
  // The camera's own motion: the body motion seen from the camera.
  const SE3 T_1_2_body = motion(8, Vec3(0.5, 0.02, 0.3));
  const SE3 T_1_2_cam = rig.T_b_c(0).inverse() * T_1_2_body * rig.T_b_c(0);
  const TwoFrames f = makeTwoFrames(rig, T_1_2_body, 200, 0.2, 0.5, r);
  const RelativePoseResult res = estimateCentralRelativePose(f.matches, optionsForNoise(0.5));
  ASSERT_EQ(res.status, RelativePoseStatus::Ok) << relativePoseStatusName(res.status);
  EXPECT_FALSE(res.metric);
  EXPECT_NEAR(res.T_1_2.t.norm(), 1.0, 1e-9);
  const double direction_error = std::acos(std::min(1.0, res.T_1_2.t.dot(T_1_2_cam.t.normalized()))) * 180 / M_PI;
  std::printf("central: direction error %.3f deg (sigma %.3f deg), rotation error %.4f deg\n", direction_error,
              res.direction_sigma_rad * 180 / M_PI, rotationErrorDeg(res.T_1_2, T_1_2_cam));
  EXPECT_LT(direction_error, 1.0);
  EXPECT_LT(rotationErrorDeg(res.T_1_2, T_1_2_cam), 0.1);
  EXPECT_LE(maskErrors(f, res.inlier_mask), 3);
}

// One camera turning on the spot: no translation direction to find; reported, not invented. Which check speaks
// first depends on the direction RANSAC drew (it is noise here): its uncertainty or the parallax behind it.
TEST(RelativePose, CentralReportsPureRotation) {
  const Rig rig = Rig{{{"cam0", pinholeRadtan(), SE3(), 0}}, std::nullopt};
  SceneRandom r(13);
  const TwoFrames f = makeTwoFrames(rig, motion(6, Vec3::Zero()), 200, 0.1, 0.5, r);
  const RelativePoseResult res = estimateCentralRelativePose(f.matches, optionsForNoise(0.5));
  std::printf("pure rotation: status %s, direction sigma %.3g rad, parallax %.3g rad\n",
              relativePoseStatusName(res.status), res.direction_sigma_rad, res.median_parallax_rad);
  EXPECT_TRUE(res.status == RelativePoseStatus::DirectionUnobservable || res.status == RelativePoseStatus::LowParallax)
      << relativePoseStatusName(res.status);
  EXPECT_LT(res.median_parallax_rad, RelativePoseOptions{}.min_median_parallax_rad);
  EXPECT_LT(rotationErrorDeg(res.T_1_2, f.T_1_2), 0.1);  // the rotation itself is known
}

TEST(RelativePose, DeterministicAndReportsBadInput) {
  const Rig rig = nonOverlappingRig();
  SceneRandom r(17);
  const TwoFrames f = makeTwoFrames(rig, motion(15, Vec3(0.5, 0.0, 0.5)), 150, 0.2, 0.5, r);
  const RelativePoseResult a = estimateGeneralizedRelativePose(rig, f.matches);
  const RelativePoseResult b = estimateGeneralizedRelativePose(rig, f.matches);
  EXPECT_EQ(a.ransac_iterations, b.ransac_iterations);
  EXPECT_EQ((a.T_1_2.matrix() - b.T_1_2.matrix()).norm(), 0.0);
  EXPECT_EQ(a.inlier_mask, b.inlier_mask);
  // Too few matches, and a one-camera rig (no metric scale).
  const std::vector<RelativeCorrespondence> few(f.matches.begin(), f.matches.begin() + 10);
  EXPECT_EQ(estimateGeneralizedRelativePose(rig, few).status, RelativePoseStatus::TooFewCorrespondences);
  EXPECT_EQ(estimateGeneralizedRelativePose(monoRig(), f.matches).status, RelativePoseStatus::ScaleUnobservable);
}

// Noise-free samples of five matches: one of the solver's essential matrices is the true one, as one of OpenGV's
// (Nister's solver, the anchor) is.
TEST(RelativePoseSolvers, FivePointFindsTheTrueEssentialMatrix) {
  const Rig rig = Rig{{{"cam0", pinholeRadtan(), SE3(), 0}}, std::nullopt};
  SceneRandom r(19);
  int ours_found = 0, opengv_found = 0, trials = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const TwoFrames f = makeTwoFrames(rig, motion(3 + trial % 20, Vec3(0.3, 0.1 * (trial % 3), 0.5)), 5, 0.0, 0.0, r);
    if (f.matches.size() < 5) continue;
    ++trials;
    const Mat3 E_true = hat(f.T_1_2.t.normalized()) * f.T_1_2.R;
    std::array<Vec3, 5> d1, d2;
    opengv::bearingVectors_t b1, b2;
    for (int i = 0; i < 5; ++i) {
      d1[i] = f.matches[i].bearing1.normalized();
      d2[i] = f.matches[i].bearing2.normalized();
      b1.push_back(d1[i]);
      b2.push_back(d2[i]);
    }
    std::array<Mat3, 10> E;
    const int n = relative_pose_detail::fivePointEssential(d1, d2, E);
    double best = INFINITY;
    for (int k = 0; k < n; ++k) {
      best = std::min(best, essentialDistance(E[k], E_true));
      for (int i = 0; i < 5; ++i) EXPECT_NEAR(d1[i].dot(E[k] * d2[i]), 0.0, 1e-9) << trial;  // every solution fits
    }
    ours_found += best < 1e-6 ? 1 : 0;
    // OpenGV's adapter takes (viewpoint 1, viewpoint 2) and returns E with f1' E f2 = 0 up to transposition.
    const opengv::relative_pose::CentralRelativeAdapter adapter(b1, b2);
    double best_opengv = INFINITY;
    for (const opengv::essential_t& e : opengv::relative_pose::fivept_nister(adapter, {0, 1, 2, 3, 4}))
      best_opengv = std::min({best_opengv, essentialDistance(e, E_true), essentialDistance(e.transpose(), E_true)});
    opengv_found += best_opengv < 1e-6 ? 1 : 0;
  }
  std::printf("five-point: true E found in %d of %d samples (OpenGV's Nister: %d)\n", ours_found, trials, opengv_found);
  EXPECT_GE(trials, 40);
  EXPECT_EQ(ours_found, trials);
  EXPECT_GE(ours_found, opengv_found);
}

// Noise-free: the linear generalized solver recovers the metric pose of a rig whose matches cross cameras and of
// one whose matches all stay within their cameras (where the solution E = 0, R = I fits every match too).
TEST(RelativePoseSolvers, LinearGeneralizedRecoversMetricPose) {
  struct Case {
    const char* name;
    Rig rig;
    bool cross_camera;
  };
  for (const Case& c : {Case{"three overlapping cameras, across cameras", trinocularRig(), true},
                        Case{"non-overlapping, within cameras", wideNonOverlappingRig(), false}}) {
    SceneRandom r(23);
    const TwoFrames f = makeTwoFrames(c.rig, motion(25, Vec3(0.4, 0.05, 0.6)), 60, 0.0, 0.0, r, c.cross_camera);
    const std::vector<relative_pose_detail::RayPair> rays = bodyRays(c.rig, f);
    const std::vector<uint8_t> all(rays.size(), 1);
    std::array<SE3, 2> poses;
    ASSERT_TRUE(relative_pose_detail::linearGeneralizedPose(rays, all, poses)) << c.name;
    double best = INFINITY;
    for (const SE3& T : poses) best = std::min(best, (T.t - f.T_1_2.t).norm() + rotationAngle(T.R, f.T_1_2.R));
    std::printf("%s: linear 17-point pose error %.2e\n", c.name, best);
    EXPECT_LT(best, 1e-6) << c.name;
  }
}

// A rig that loses tracking after the warm-up starts a new map through the relative pose: once constructed, the
// estimator allocates nothing, in the generalized and the central case.
TEST(RelativePoseSolvers, AnEstimatorRefusesARigLargerThanItWasBuiltFor) {
  const Rig rig = trinocularRig();
  SceneRandom r(31);
  const TwoFrames f = makeTwoFrames(rig, motion(10, Vec3(0.3, 0, 0.5)), 100, 0.0, 0.3, r);
  RelativePoseEstimator estimator(200, 2);
  EXPECT_THROW(estimator.generalized(rig, f.matches, optionsForNoise(0.3)), InputError);
}

TEST(RelativePoseSolvers, EstimatorAllocatesNothingAfterConstruction) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  const Rig rig = wideNonOverlappingRig();
  SceneRandom r(29);
  const TwoFrames f = makeTwoFrames(rig, motion(30, Vec3(0.6, 0.05, 0.8)), 300, 0.2, 0.3, r);
  RelativePoseEstimator estimator(400, rig.size());
  const alloc::ThreadScope scope;
  const RelativePoseResult& g = estimator.generalized(rig, f.matches, optionsForNoise(0.3));
  const RelativePoseStatus generalized_status = g.status;
  const RelativePoseResult& c = estimator.central(f.matches, optionsForNoise(0.3));
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_EQ(generalized_status, RelativePoseStatus::Ok);  // the calls did the whole work
  EXPECT_GT(c.ransac_iterations, 0);
}
