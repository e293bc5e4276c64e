// The relocalizer's guided stage on a scene made for its known trap: a far wall, whose points alone leave the pose
// free to trade pitch for height, and nearer points whose keypoints have decoys (similar texture) exactly where a
// pose 1 m too low and pitched to keep the wall in place would project them. A narrow search from that hypothesis
// finds only the decoys and confirms it; the guided stage must find the true keypoints and the true pose.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "../geometry/pose_scenes.hpp"
#include "mcslam/places/relocalizer.hpp"

namespace mcslam {
namespace {

constexpr int kMaxFeatures = 512;

Descriptor randomDescriptor(std::mt19937_64& rng) { return {rng(), rng(), rng(), rng()}; }

Descriptor flipBits(Descriptor d, int bits, std::mt19937_64& rng) {
  std::vector<int> order(256);
  for (int i = 0; i < 256; ++i) order[static_cast<std::size_t>(i)] = i;
  std::shuffle(order.begin(), order.end(), rng);
  for (int i = 0; i < bits; ++i) {
    const int b = order[static_cast<std::size_t>(i)];
    d[static_cast<std::size_t>(b / 64)] ^= uint64_t{1} << (b % 64);
  }
  return d;
}

struct Scene {
  Rig rig;
  PlaceMap map{2, kMaxFeatures};
  int keyframe = -1;
  FrameFeatures frame{1, kMaxFeatures};
  SE3 truth, hypothesis;

  Scene() {
    rig.cameras.push_back(test::rigCamera("cam0", test::pinholeRadtan(), {0, 0, 0}, {0, 0, 0}));
    keyframe = map.createKeyframe(map.createSegment(SE3()), 0, 0, SE3(), SE3());
    truth = SE3(Mat3::Identity(), Vec3(0, 0, -6));  // 6 m behind the keyframe, looking the same way (z)
    // 1 m lower (y points down) and pitched so that the wall's centre, 26 m ahead, stays where it was.
    const Vec3 offset(0, 1, 0);
    hypothesis = SE3(Eigen::AngleAxisd(std::atan2(1.0, 26.0), Vec3::UnitX()).toRotationMatrix(), truth.t + offset);
    frame.present[0] = 1;
  }

  void addPoint(const Vec3& p_w, bool with_decoy, std::mt19937_64& rng) {
    PlacePoint point;
    point.p_k = p_w.cast<float>();
    point.cam = 0;
    point.landmark_id = map.keyframe(keyframe).point_count;
    point.descriptor = randomDescriptor(rng);
    ASSERT_TRUE(map.addPoint(keyframe, point));
    addKeypoint(truth, p_w, flipBits(point.descriptor, 8, rng), rng);
    if (with_decoy) addKeypoint(hypothesis, p_w, flipBits(point.descriptor, 24, rng), rng);
  }

  void addKeypoint(const SE3& T_w_b, const Vec3& p_w, const Descriptor& descriptor, std::mt19937_64& rng) {
    std::normal_distribution<double> noise(0.0, 0.3);
    Vec2 uv;
    ASSERT_TRUE(rig.model(0).project(T_w_b.inverse() * p_w, uv));
    uv += Vec2(noise(rng), noise(rng));
    FeatureSet& set = frame.sets[0];
    const auto k = static_cast<std::size_t>(set.count++);
    set.keypoints[k] = Keypoint{static_cast<float>(uv.x()), static_cast<float>(uv.y()), 0, 1, 0};
    set.descriptors[k] = descriptor;
    frame.valid[0][k] = rig.model(0).unproject(uv, frame.bearings[0][k]) ? 1 : 0;
  }
};

TEST(GuidedSearch, DecoysWhereAWrongHypothesisProjectsDoNotConfirmIt) {
  std::mt19937_64 rng(21);
  Scene scene;
  for (int i = 0; i < 16; ++i)  // the far wall, 20 m ahead of the keyframe
    for (int j = 0; j < 10; ++j) scene.addPoint(Vec3(-6.0 + 0.8 * i, -3.6 + 0.8 * j, 20.0), false, rng);
  std::uniform_real_distribution<double> x(-2.5, 2.5), y(-1.8, 1.8), z(6.0, 10.0);
  for (int i = 0; i < 60; ++i) scene.addPoint(Vec3(x(rng), y(rng), z(rng)), true, rng);
  scene.map.finishKeyframe(scene.keyframe);

  PlacesOptions options;
  Relocalizer relocalizer(scene.rig, options, 1.2f, kMaxFeatures);
  const PoseRefinementResult found =
      relocalizer.poseByProjection(scene.frame, scene.map, scene.keyframe, scene.hypothesis);
  ASSERT_TRUE(found.success);
  const SE3 error = scene.truth.inverse() * found.T_w_b;
  EXPECT_LT(error.t.norm(), 0.05) << "the hypothesis was 1 m off";
  EXPECT_LT(so3Log(error.R).norm(), 0.2 * M_PI / 180);
  EXPECT_GE(found.num_inliers, 200);  // the wall and the near points' true keypoints
}

}  // namespace
}  // namespace mcslam
