// Matching quality against cv::ORB on view pairs with known geometry: the correct matches of our
// extractor must be within 10% of cv::ORB's at the same feature count.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

#include <cstdio>

#include "mcslam/features/orb_extractor.hpp"
#include "orb_match_util.hpp"
#include "orb_test_images.hpp"

namespace mcslam::test {
namespace {

struct PairCase {
  const char* name;
  uint64_t seed;
  double angle, scale, tilt_x, tilt_y;
};

struct Counts {
  int features = 0, matches = 0, correct = 0;
};

Counts scoreOurs(const Image& a, const Image& b, int features,
                 const std::function<bool(double, double, double&, double&)>& map) {
  OrbOptions options;
  options.max_features = features;
  OrbExtractor extractor(options, a.width(), a.height());
  FeatureSet fa(features), fb(features);
  extractor.extract(a.view(), fa);
  extractor.extract(b.view(), fb);
  const auto matches = mutualRatioMatches(fa, fb);
  return {std::min(fa.count, fb.count), static_cast<int>(matches.size()), countCorrect(fa, fb, matches, map)};
}

Counts scoreOpenCv(const Image& a, const Image& b, int features,
                   const std::function<bool(double, double, double&, double&)>& map) {
  cv::setNumThreads(1);
  auto orb = cv::ORB::create(features);
  auto run = [&](const Image& image) {
    const cv::Mat mat(image.height(), image.width(), CV_8U, const_cast<uint8_t*>(image.data()));
    std::vector<cv::KeyPoint> keypoints;
    cv::Mat descriptors;
    orb->detectAndCompute(mat, cv::noArray(), keypoints, descriptors);
    return toFeatureSet(keypoints, descriptors);
  };
  const FeatureSet fa = run(a), fb = run(b);
  const auto matches = mutualRatioMatches(fa, fb);
  return {std::min(fa.count, fb.count), static_cast<int>(matches.size()), countCorrect(fa, fb, matches, map)};
}

class OrbMatchingVsOpenCv : public ::testing::TestWithParam<PairCase> {};

TEST_P(OrbMatchingVsOpenCv, CorrectMatchesWithinTenPercent) {
  const PairCase& c = GetParam();
  constexpr int kWidth = 720, kHeight = 540, kFeatures = 1000;
  const ProceduralScene scene(c.seed);
  const auto H1 = viewHomography(kWidth / 2.0, kHeight / 2.0, 0, 1, 150, 150);
  const auto H2 = viewHomography(kWidth / 2.0, kHeight / 2.0, c.angle, c.scale, 150, 150, c.tilt_x, c.tilt_y);
  Image a, b;
  scene.render(H1, a, kWidth, kHeight);
  scene.render(H2, b, kWidth, kHeight);
  addNoise(a, 2.0, c.seed + 1);
  addNoise(b, 2.0, c.seed + 2);
  const auto H2_inv = inverse(H2);
  auto a_to_b = [&](double u, double v, double& x, double& y) {
    double sx, sy;
    applyHomography(H1, u, v, sx, sy);
    applyHomography(H2_inv, sx, sy, x, y);
    return x >= 0 && y >= 0 && x <= kWidth - 1 && y <= kHeight - 1;
  };
  const Counts ours = scoreOurs(a, b, kFeatures, a_to_b);
  const Counts cv_orb = scoreOpenCv(a, b, kFeatures, a_to_b);
  std::printf("[%s] correct matches: mcslam %d of %d (features %d), cv::ORB %d of %d (features %d)\n", c.name,
              ours.correct, ours.matches, ours.features, cv_orb.correct, cv_orb.matches, cv_orb.features);
  EXPECT_GE(ours.features, cv_orb.features * 0.98);  // the comparison is at the same feature count
  EXPECT_GT(cv_orb.correct, 50);                     // the pair is matchable at all
  EXPECT_GE(ours.correct, 0.9 * cv_orb.correct);
}

INSTANTIATE_TEST_SUITE_P(SyntheticPairs, OrbMatchingVsOpenCv,
                         ::testing::Values(PairCase{"rotate15_scale1.15", 11, 0.26, 1.15, 0, 0},
                                           PairCase{"rotate40", 12, 0.70, 1.0, 0, 0},
                                           PairCase{"zoomout_tilt", 13, -0.1, 0.85, 2e-4, -1.5e-4},
                                           PairCase{"rotate90_scale1.3", 14, 1.5708, 1.3, 0, 0}),
                         [](const auto& param) { return std::string("Case") + std::to_string(param.index); });

}  // namespace
}  // namespace mcslam::test
