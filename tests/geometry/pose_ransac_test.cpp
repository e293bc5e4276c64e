#include <gtest/gtest.h>

#include "mcslam/geometry/absolute_pose_ransac.hpp"
#include "pose_scenes.hpp"

using namespace mcslam;
using namespace mcslam::test;

namespace {

int maskErrors(const PoseScene& scene, std::span<const uint8_t> mask) {
  int wrong = 0;
  for (size_t i = 0; i < scene.is_inlier.size(); ++i) wrong += (mask[i] != 0) != (scene.is_inlier[i] != 0) ? 1 : 0;
  return wrong;
}

}  // namespace

// 500 correspondences, half of them gross outliers, spread over every camera of every rig shape.
// Noise 0.5 px against sigma 1 px, so the chi-square test rejects no true inlier in practice and
// the inlier set must be exactly right.
TEST(AbsolutePoseRansac, FindsPoseAndExactInlierSetWithHalfOutliers) {
  for (const NamedRig& shape : allRigShapes()) {
    SceneRandom r(17);
    AbsolutePoseRansac ransac(shape.rig, 500);
    for (int trial = 0; trial < 4; ++trial) {
      const PoseScene scene = makePoseScene(shape.rig, 500, 0.5, 0.5, 1.0, r);
      const AbsolutePoseRansacResult res = ransac.estimate(scene.observations);
      ASSERT_TRUE(res.ok()) << shape.name << " " << absolutePoseStatusName(res.status);
      EXPECT_EQ(res.num_inliers, 250) << shape.name;
      EXPECT_EQ(maskErrors(scene, res.inlier_mask), 0) << shape.name;
      EXPECT_LT(rotationErrorDeg(res.T_w_b, scene.T_w_b), 0.05) << shape.name;
      EXPECT_LT(translationError(res.T_w_b, scene.T_w_b), 0.01) << shape.name;
      EXPECT_LT(res.iterations, ransac.options().max_iterations) << shape.name;  // adaptive stop
    }
  }
}

// Same seed, same input: same result, sample for sample. Another seed still finds the pose.
TEST(AbsolutePoseRansac, IsDeterministicForAGivenSeed) {
  const Rig rig = nonOverlappingRig();
  SceneRandom r(19);
  const PoseScene scene = makePoseScene(rig, 200, 0.5, 1.0, 1.0, r);
  AbsolutePoseRansacOptions options;
  options.seed = 1234;
  AbsolutePoseRansac a(rig, 200, options), b(rig, 200, options);
  const AbsolutePoseRansacResult ra = a.estimate(scene.observations);
  const AbsolutePoseRansacResult rb = b.estimate(scene.observations);
  ASSERT_TRUE(ra.ok());
  EXPECT_EQ(ra.iterations, rb.iterations);
  EXPECT_EQ(ra.num_inliers, rb.num_inliers);
  EXPECT_EQ((ra.T_w_b.matrix() - rb.T_w_b.matrix()).norm(), 0.0);
  options.seed = 99;
  AbsolutePoseRansac c(rig, 200, options);
  const AbsolutePoseRansacResult rc = c.estimate(scene.observations);
  ASSERT_TRUE(rc.ok());
  EXPECT_NE(rc.iterations, 0);
  EXPECT_LT(rotationErrorDeg(rc.T_w_b, scene.T_w_b), 0.1);
}

// At 90% outliers and only 20 samples, random sampling alone rarely succeeds; the motion-model
// prediction is scored as a hypothesis and carries the estimate.
TEST(AbsolutePoseRansac, MotionModelPredictionIsAHypothesis) {
  const Rig rig = stereoRig();
  SceneRandom r(29);
  const PoseScene scene = makePoseScene(rig, 300, 0.9, 0.5, 1.0, r);
  AbsolutePoseRansacOptions options;
  options.max_iterations = 20;
  AbsolutePoseRansac ransac(rig, 300, options);
  const SE3 predicted = scene.T_w_b * SE3::exp((Vec6() << 0.01, -0.01, 0.005, 0.002, 0.001, -0.002).finished());
  const AbsolutePoseRansacResult res = ransac.estimate(scene.observations, &predicted);
  ASSERT_TRUE(res.ok());
  EXPECT_TRUE(res.from_prediction);
  EXPECT_EQ(res.num_inliers, 30);
  EXPECT_LT(rotationErrorDeg(res.T_w_b, scene.T_w_b), 0.05);
  EXPECT_LT(translationError(res.T_w_b, scene.T_w_b), 0.01);
}

TEST(AbsolutePoseRansac, ReportsFailuresAsStatus) {
  const Rig rig = monoRig();
  SceneRandom r(37);
  AbsolutePoseRansac ransac(rig, 100);
  const PoseScene big = makePoseScene(rig, 150, 0.0, 0.5, 1.0, r);
  EXPECT_EQ(ransac.estimate(big.observations).status, AbsolutePoseStatus::OverCapacity);
  const PoseScene tiny = makePoseScene(rig, 2, 0.0, 0.5, 1.0, r);
  EXPECT_EQ(ransac.estimate(tiny.observations).status, AbsolutePoseStatus::TooFewCorrespondences);
  // Nothing but outliers: no hypothesis gathers min_inliers.
  const PoseScene junk = makePoseScene(rig, 100, 1.0, 0.5, 1.0, r);
  const AbsolutePoseRansacResult res = ransac.estimate(junk.observations);
  EXPECT_EQ(res.status, AbsolutePoseStatus::NoConsensus);
  EXPECT_EQ(res.iterations, ransac.options().max_iterations);
}

namespace {

// A row of five forward cameras in a hall: most points lie on the far wall, in a band of the image at 12-16 m,
// and 5% are near, above and below it. A vertical shift with the pitch that hides it keeps most far points
// within the threshold, and the adaptive stop can take such a hypothesis after a few samples; only the near
// points tell. The prediction, refined over every correspondence, competes with the winner.
PoseScene farWallScene(const Rig& rig, const CameraModel& m, SceneRandom& r) {
  PoseScene scene;
  scene.T_w_b = r.pose(5.0);
  while (scene.observations.size() < 3000) {
    const int cam = r.index(rig.size());
    const bool near = scene.observations.size() % 20 == 0;
    const double row = !near ? r.uniform(200, 330) : r.uniform(0, 1) < 0.5 ? r.uniform(10, 190) : r.uniform(350, 530);
    Vec3 bearing;
    if (!m.unproject(Vec2(r.uniform(10, 709), row), bearing)) continue;
    const double depth = near ? r.uniform(2.0, 6.0) : r.uniform(12.0, 16.0);
    const Vec3 X = scene.T_w_b * (rig.T_b_c(cam) * (bearing * depth));
    PoseObservation o;
    if (!observe(rig, cam, scene.T_w_b, X, 1.0, 1.0, r, o)) continue;
    const bool outlier = r.uniform(0, 1) < 0.1;
    if (outlier) o.point_w = pointSeenBy(rig, cam, scene.T_w_b, r, 2.0, 16.0);
    scene.observations.push_back(o);
    scene.is_inlier.push_back(outlier ? 0 : 1);
  }
  return scene;
}

}  // namespace

TEST(AbsolutePoseRansac, AFarWallDoesNotHideAVerticalShiftFromThePrediction) {
  const CameraModel m(720, 540, 890.0, 890.0, 360, 270, Distortion::RadTan, {-0.2, 0.2, 0, 0});
  Rig rig;
  for (int i = 0; i < 5; ++i) rig.cameras.push_back(rigCamera("cam", m, {0, 0, 0}, {0.165 * i, 0, 0}));
  double worst = 0;
  for (uint32_t seed = 1; seed <= 40; ++seed) {
    SceneRandom r(seed);
    const PoseScene scene = farWallScene(rig, m, r);
    AbsolutePoseRansacOptions options;
    options.seed = seed;
    options.max_iterations = 300;  // the tracker's
    AbsolutePoseRansac ransac(rig, 3000, options);
    const SE3 predicted = scene.T_w_b * SE3::exp((Vec6() << 0.01, -0.01, 0.01, 0.002, 0.001, -0.002).finished());
    const AbsolutePoseRansacResult res = ransac.estimate(scene.observations, &predicted);
    ASSERT_TRUE(res.ok()) << "seed " << seed;
    worst = std::max(worst, translationError(res.T_w_b, scene.T_w_b));
  }
  EXPECT_LT(worst, 0.01) << "the worst of 40 scenes, m";
}
