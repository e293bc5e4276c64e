#include <gtest/gtest.h>

#include "mcslam/geometry/relative_pose.hpp"
#include "mcslam/geometry/relative_pose_refinement.hpp"
#include "pose_scenes.hpp"

using namespace mcslam;
using namespace mcslam::test;

namespace {

// Bearing of world point X seen by camera `cam` of the rig at body pose T_w_b, through the pixel
// with noise. False when it is not in the image.
bool noisyBearing(const Rig& rig, int cam, const SE3& T_w_b, const Vec3& X, double noise_px, SceneRandom& r,
                  Vec3& bearing) {
  Vec2 uv;
  if (!rig.model(cam).project(rig.T_b_c(cam).inverse() * (T_w_b.inverse() * X), uv)) return false;
  if (!rig.model(cam).inImage(uv)) return false;
  uv += Vec2(r.gaussian(noise_px), r.gaussian(noise_px));
  return rig.model(cam).unproject(uv, bearing);
}

struct TwoFrames {
  SE3 T_1_2;
  std::vector<RelativeCorrespondence> matches;
  std::vector<uint8_t> is_inlier;
};

// Matches between frame 1 (the world) and frame 2 = T_1_2. cross_camera: the point is seen by
// another camera in frame 2 (overlapping rigs); otherwise by the same camera.
TwoFrames makeTwoFrames(const Rig& rig, const SE3& T_1_2, int n, double outlier_fraction, double noise_px,
                        SceneRandom& r, bool cross_camera = false) {
  TwoFrames f;
  f.T_1_2 = T_1_2;
  const int num_outliers = static_cast<int>(std::round(n * outlier_fraction));
  int attempts = 0;
  while (static_cast<int>(f.matches.size()) < n && ++attempts < 100000) {
    RelativeCorrespondence m;
    m.camera1 = r.index(rig.size());
    m.camera2 = cross_camera ? (m.camera1 + 1) % rig.size() : m.camera1;
    const Vec3 X = pointSeenBy(rig, m.camera1, SE3(), r, 2.0, 12.0);
    if (!noisyBearing(rig, m.camera1, SE3(), X, noise_px, r, m.bearing1)) continue;
    if (!noisyBearing(rig, m.camera2, T_1_2, X, noise_px, r, m.bearing2)) continue;
    const bool outlier = static_cast<int>(f.matches.size()) < num_outliers;
    if (outlier) {
      // Another point's bearing in frame 2, far from the right one.
      const Vec3 Y = pointSeenBy(rig, m.camera2, T_1_2, r, 2.0, 12.0);
      Vec3 wrong;
      if (!noisyBearing(rig, m.camera2, T_1_2, Y, 0.0, r, wrong) ||
          std::acos(std::min(1.0, wrong.dot(m.bearing2))) < 0.05)
        continue;
      m.bearing2 = wrong;
    }
    f.matches.push_back(m);
    f.is_inlier.push_back(outlier ? 0 : 1);
  }
  return f;
}

// Options matching the simulated noise: pixel sigma over the focal length, with 20% for the
// lens distortion that stretches the angle of a pixel toward the image edges.
RelativePoseOptions optionsForNoise(double noise_px) {
  RelativePoseOptions o;
  o.bearing_sigma_rad = 1.2 * noise_px / pinholeRadtan().fx();
  return o;
}

// The non-overlapping rig with its cameras twice as far from the centre (about 0.3 m: a robot).
Rig wideNonOverlappingRig() {
  Rig rig = nonOverlappingRig();
  for (RigCamera& c : rig.cameras) c.T_b_c.t *= 2.0;
  return rig;
}

SE3 motion(double yaw_deg, const Vec3& t) {
  return SE3(so3Exp(Vec3(0.1, 1.0, 0.05).normalized() * yaw_deg * M_PI / 180), t);
}

int maskErrors(const TwoFrames& f, const std::vector<uint8_t>& mask) {
  int wrong = 0;
  for (size_t i = 0; i < mask.size(); ++i) wrong += (mask[i] != 0) != (f.is_inlier[i] != 0) ? 1 : 0;
  return wrong;
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
      const double h = 1e-7;
      SE3 Tp = T, Tm = T;
      if (k < 3) {
        Tp.t[k] += h;
        Tm.t[k] -= h;
      } else {
        Tp.R = T.R * so3Exp(Vec3::Unit(k - 3) * h);
        Tm.R = T.R * so3Exp(-Vec3::Unit(k - 3) * h);
      }
      const double numeric =
          (relative_pose_detail::sampsonError(p, Tp) - relative_pose_detail::sampsonError(p, Tm)) / (2 * h);
      EXPECT_NEAR(numeric, J(k), 1e-5 * std::max(1.0, std::abs(numeric))) << k;
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

// An overlapping pair with matches across cameras has metric scale even without rotation.
TEST(RelativePose, GeneralizedCrossCameraMatchesGiveScaleWithoutRotation) {
  const Rig rig = stereoRig();
  SceneRandom r(9);
  const TwoFrames f = makeTwoFrames(rig, motion(0, Vec3(0.1, 0.0, 0.5)), 300, 0.1, 0.5, r, true);
  const RelativePoseResult res = estimateGeneralizedRelativePose(rig, f.matches, optionsForNoise(0.5));
  ASSERT_EQ(res.status, RelativePoseStatus::Ok) << relativePoseStatusName(res.status);
  EXPECT_LT((res.T_1_2.t - f.T_1_2.t).norm() / f.T_1_2.t.norm(), 0.05);
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

// One camera turning on the spot: no translation direction to find; reported, not invented.
TEST(RelativePose, CentralReportsPureRotation) {
  const Rig rig = Rig{{{"cam0", pinholeRadtan(), SE3(), 0}}, std::nullopt};
  SceneRandom r(13);
  const TwoFrames f = makeTwoFrames(rig, motion(6, Vec3::Zero()), 200, 0.1, 0.5, r);
  const RelativePoseResult res = estimateCentralRelativePose(f.matches, optionsForNoise(0.5));
  std::printf("pure rotation: status %s, direction sigma %.3g rad, parallax %.3g rad\n",
              relativePoseStatusName(res.status), res.direction_sigma_rad, res.median_parallax_rad);
  EXPECT_EQ(res.status, RelativePoseStatus::DirectionUnobservable) << relativePoseStatusName(res.status);
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
