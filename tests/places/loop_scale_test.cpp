// The scale of a Sim(3) loop: the median ratio of the place's point distances to the keyframe's own, robust to
// wrong matches, with an uncertainty that shrinks with more points and grows with their spread; too few points
// give none.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "mcslam/places/loop_scale.hpp"

namespace mcslam {
namespace {

Rig oneCamera() {
  Rig rig;
  RigCamera c;
  c.T_b_c = SE3(Mat3::Identity(), Vec3(0.1, 0, 0));  // the camera sits off the body's origin
  rig.cameras.push_back(c);
  return rig;
}

struct Scene {
  std::vector<PlaceMatch> inliers;
  std::vector<Eigen::Vector3f> own;  // by keypoint
};

// `n` keypoints, each with the keyframe's own point at some depth and the place's point `scale` times as far from
// the camera (the place's unit), seen from T_w_b; `wrong` of them are matched to a point elsewhere.
Scene scene(int n, double scale, int wrong, double noise, const SE3& T_w_b, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> lateral(-2, 2), depth(2, 12);
  std::normal_distribution<double> jitter(0, noise);
  const Vec3 centre(0.1, 0, 0);
  Scene s;
  s.own.assign(static_cast<std::size_t>(n + 5), Eigen::Vector3f::Constant(std::nanf("")));
  for (int k = 0; k < n; ++k) {
    const Vec3 own = centre + Vec3(lateral(rng), lateral(rng), depth(rng));
    s.own[static_cast<std::size_t>(k)] = own.cast<float>();
    Vec3 theirs = centre + scale * (own - centre) * std::exp(jitter(rng));
    if (k < wrong) theirs = centre + 20 * (own - centre);
    s.inliers.push_back({0, k, T_w_b * theirs, nullptr});
  }
  s.inliers.push_back({0, n + 2, T_w_b * Vec3(0, 0, 4), nullptr});  // a keypoint without a point of its own
  return s;
}

TEST(LoopScale, TheMedianRatioIsTheScaleDespiteWrongMatches) {
  const SE3 T_w_b(so3Exp(Vec3(0.1, -0.3, 1.2)), Vec3(4, -2, 1));
  const Scene s = scene(200, 0.62, 40, 0.02, T_w_b, 1);
  std::vector<double> scratch(512);
  const LoopScale r = loopScale(s.inliers, s.own, static_cast<int>(s.own.size()), T_w_b, oneCamera(), scratch);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(r.samples, 200);
  EXPECT_NEAR(std::log(r.scale), std::log(0.62), 0.01);
  EXPECT_GT(r.sigma_log_scale, 0.0005);
  EXPECT_LT(r.sigma_log_scale, 0.01);
}

TEST(LoopScale, MorePointsAndLessSpreadMakeItSurer) {
  const SE3 T_w_b;
  std::vector<double> scratch(2048);
  const auto sigma = [&](int n, double noise) {
    const Scene s = scene(n, 1.5, 0, noise, T_w_b, 2);
    return loopScale(s.inliers, s.own, static_cast<int>(s.own.size()), T_w_b, oneCamera(), scratch).sigma_log_scale;
  };
  EXPECT_LT(sigma(800, 0.05), 0.7 * sigma(100, 0.05));
  EXPECT_LT(sigma(200, 0.01), 0.5 * sigma(200, 0.05));
}

TEST(LoopScale, TooFewPointsOfItsOwnGiveNoScale) {
  const SE3 T_w_b;
  const Scene s = scene(19, 2.0, 0, 0.01, T_w_b, 3);
  std::vector<double> scratch(64);
  const LoopScale r = loopScale(s.inliers, s.own, static_cast<int>(s.own.size()), T_w_b, oneCamera(), scratch);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.samples, 19);
}

// Each place keyframe's matches measure its own unit: a group whose keyframes were made in different units.
TEST(LoopScale, EachPlaceKeyframesMatchesMeasureItsOwnUnit) {
  const SE3 T_w_b;
  Scene s = scene(100, 1.2, 0, 0.01, T_w_b, 5);
  const Scene other = scene(60, 0.7, 0, 0.01, T_w_b, 6);
  for (PlaceMatch& m : s.inliers) m.keyframe = 3;
  for (PlaceMatch m : other.inliers) {
    m.kp += 1000;  // keypoints after the first scene's
    m.keyframe = 8;
    s.inliers.push_back(m);
  }
  s.own.resize(1000 + other.own.size(), Eigen::Vector3f::Constant(std::nanf("")));
  std::copy(other.own.begin(), other.own.end(), s.own.begin() + 1000);
  std::vector<double> scratch(512);
  const auto at = [&](int keyframe) {
    return loopScale(s.inliers, s.own, static_cast<int>(s.own.size()), T_w_b, oneCamera(), scratch, keyframe);
  };
  EXPECT_NEAR(at(3).scale, 1.2, 0.01);
  EXPECT_NEAR(at(8).scale, 0.7, 0.01);
  EXPECT_EQ(at(8).samples, 60);
  EXPECT_FALSE(at(5).ok);  // none of its points matched
}

// Before a rig without overlap knows its unit, its motion is in one unit and its lever arms in metres: each
// camera's depths come out in a unit of their own, and each camera's matches measure it.
TEST(LoopScale, EachCameraOfAPlaceMeasuresItsOwnUnit) {
  const SE3 T_w_b;
  Rig rig = oneCamera();
  rig.cameras.push_back(rig.cameras[0]);  // a second camera at the same centre (scene() puts points about it)
  Scene s = scene(80, 1.2, 0, 0.01, T_w_b, 7);
  const Scene second = scene(50, 0.9, 0, 0.01, T_w_b, 8);
  const int per_camera = 200;
  s.own.resize(2 * per_camera, Eigen::Vector3f::Constant(std::nanf("")));
  for (PlaceMatch m : second.inliers) {
    m.cam = 1;
    s.inliers.push_back(m);
  }
  std::copy(second.own.begin(), second.own.end(), s.own.begin() + per_camera);
  for (PlaceMatch& m : s.inliers) m.keyframe = 4;
  std::vector<double> scratch(512);
  const auto of = [&](int cam) { return loopScale(s.inliers, s.own, per_camera, T_w_b, rig, scratch, 4, cam); };
  EXPECT_NEAR(of(0).scale, 1.2, 0.01);
  EXPECT_EQ(of(0).samples, 80);
  EXPECT_NEAR(of(1).scale, 0.9, 0.01);
  EXPECT_EQ(of(1).samples, 50);
  const LoopScale both = loopScale(s.inliers, s.own, per_camera, T_w_b, rig, scratch, 4);
  EXPECT_EQ(both.samples, 130);  // the keyframe's, all cameras
}

// A place made in a known unit takes any loop; one made while the unit was uncertain takes a loop only when the
// keyframe, in a known unit itself, measures it in the same unit within the measurement's error.
TEST(LoopScale, APlaceOfAnUncertainUnitTakesALoopOnlyInTheSameUnit) {
  const SE3 T_w_b;
  std::vector<double> scratch(512);
  const auto measured = [&](double scale) {
    const Scene s = scene(200, scale, 10, 0.02, T_w_b, 4);
    return loopScale(s.inliers, s.own, static_cast<int>(s.own.size()), T_w_b, oneCamera(), scratch);
  };
  const LoopScale same = measured(1.0), other = measured(1.25);
  ASSERT_TRUE(same.ok && other.ok);
  EXPECT_EQ(placeUnit(0.02, 0.01, other), PlaceUnit::Known);  // made in a known unit: its depths are not in doubt
  EXPECT_EQ(placeUnit(1.0, 0.01, same), PlaceUnit::Known);
  EXPECT_EQ(placeUnit(1.0, 0.01, other), PlaceUnit::Other);
  EXPECT_EQ(placeUnit(0.3, 0.5, other), PlaceUnit::Unmeasured);  // nothing surer to measure it with
  EXPECT_EQ(placeUnit(1.0, 0.01, LoopScale{}), PlaceUnit::Unmeasured);
  // Within three of the measurement's standard deviations (and no less than 1.5%): the same unit.
  EXPECT_EQ(placeUnit(1.0, 0.01, measured(1.01)), PlaceUnit::Known);
  EXPECT_EQ(placeUnit(1.0, 0.01, measured(1.04)), PlaceUnit::Other);
}

}  // namespace
}  // namespace mcslam
