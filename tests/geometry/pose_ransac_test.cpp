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
