// Matching quality of our ORB against cv::ORB on rendered images of overlapping cameras (isec 1-2 and 2-3),
// at the same feature count and with the same matching (brute force, mutual nearest, ratio both ways). A match
// is correct when the rendered depth carries the keypoint of one camera to within 3 px of its partner.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

#include <cstdio>

#include "../features/orb_match_util.hpp"
#include "mcslam/features/orb_extractor.hpp"
#include "sim_frames.hpp"

using namespace mcslam;

namespace {

constexpr int kFeatures = 1000;

FeatureSet extractOurs(const Image& image) {
  OrbOptions options;
  options.max_features = kFeatures;
  OrbExtractor extractor(options, image.width(), image.height());
  FeatureSet set(kFeatures);
  extractor.extract(image.view(), set);
  return set;
}

FeatureSet extractOpenCv(const Image& image) {
  cv::setNumThreads(1);
  auto orb = cv::ORB::create(kFeatures);
  const cv::Mat mat(image.height(), image.width(), CV_8U, const_cast<uint8_t*>(image.data()));
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  orb->detectAndCompute(mat, cv::noArray(), keypoints, descriptors);
  return test::toFeatureSet(keypoints, descriptors);
}

struct Score {
  int matches = 0, correct = 0;
};

// Pixel of camera a carried to camera b through a's rendered depth.
std::function<bool(double, double, double&, double&)> depthMapping(const Rig& rig, const sim::DepthImage& depth, int a,
                                                                   int b) {
  return [&rig, &depth, a, b](double x, double y, double& u, double& v) {
    const double z = test::depthAt(depth, x, y);
    Vec3 bearing;
    if (!(z > 0) || !rig.model(a).unproject(Vec2(x, y), bearing) || !(bearing.z() > 0)) return false;
    const Vec3 p_b = rig.T_b_c(b).inverse() * (rig.T_b_c(a) * (bearing * (z / bearing.z())));
    Vec2 uv;
    if (!rig.model(b).project(p_b, uv)) return false;
    u = uv.x();
    v = uv.y();
    return true;
  };
}

}  // namespace

TEST(SimOrbMatching, CorrectMatchesBetweenOverlappingCamerasWithinTenPercentOfCvOrb) {
  sim::Simulation& sim = test::sharedSimulation("isec", "indoor");
  const int n = sim.frameCount();
  Score ours, theirs;
  for (const int frame : {n / 8, 5 * n / 8}) {
    const test::RenderedFrame f = test::renderFrame(sim, frame, {1, 2, 3});
    for (const auto& [a, b] : {std::pair{1, 2}, std::pair{2, 3}}) {
      const auto mapping = depthMapping(sim.rig(), f.depths[a], a, b);
      const FeatureSet oa = extractOurs(f.images[a]), ob = extractOurs(f.images[b]);
      const FeatureSet ca = extractOpenCv(f.images[a]), cb = extractOpenCv(f.images[b]);
      const auto om = test::mutualRatioMatches(oa, ob), cm = test::mutualRatioMatches(ca, cb);
      const int oc = test::countCorrect(oa, ob, om, mapping), cc = test::countCorrect(ca, cb, cm, mapping);
      std::printf("frame %d cams %d-%d: ours %d/%d correct, cv::ORB %d/%d\n", frame, a, b, oc,
                  static_cast<int>(om.size()), cc, static_cast<int>(cm.size()));
      ours.matches += static_cast<int>(om.size());
      ours.correct += oc;
      theirs.matches += static_cast<int>(cm.size());
      theirs.correct += cc;
    }
  }
  ASSERT_GT(theirs.correct, 400);
  EXPECT_GE(ours.correct, 0.9 * theirs.correct);
  // Precision too: no more wrong matches per match than cv::ORB (with the same 10% margin).
  EXPECT_GE(static_cast<double>(ours.correct) / ours.matches,
            0.9 * static_cast<double>(theirs.correct) / theirs.matches);
}
