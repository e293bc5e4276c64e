#include <gtest/gtest.h>

#include <random>

#include "eval_test_util.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/eval/alignment.hpp"

using namespace mcslam;

namespace {

std::vector<Vec3> randomPoints(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 2.0);
  std::vector<Vec3> pts;
  for (int i = 0; i < n; ++i) pts.emplace_back(g(rng), g(rng), g(rng));
  return pts;
}

Similarity knownSimilarity(double s) {
  Similarity S;
  S.R = Eigen::AngleAxisd(0.7, Vec3(1, -2, 0.5).normalized()).toRotationMatrix();
  S.t = Vec3(3.0, -1.0, 0.25);
  S.s = s;
  return S;
}

std::vector<Vec3> mapped(const std::vector<Vec3>& pts, const Similarity& S) {
  std::vector<Vec3> out;
  for (const Vec3& p : pts) out.push_back(S * p);
  return out;
}

}  // namespace

TEST(Umeyama, RecoversAKnownSim3) {
  const std::vector<Vec3> from = randomPoints(50, 1);
  const Similarity truth = knownSimilarity(2.5);
  const Similarity S = umeyamaAlignment(from, mapped(from, truth), true);
  EXPECT_NEAR(S.s, 2.5, 1e-10);
  EXPECT_LT((S.R - truth.R).norm(), 1e-10);
  EXPECT_LT((S.t - truth.t).norm(), 1e-9);
}

TEST(Umeyama, RecoversAKnownSE3WithUnitScale) {
  const std::vector<Vec3> from = randomPoints(30, 2);
  const Similarity truth = knownSimilarity(1.0);
  const Similarity S = umeyamaAlignment(from, mapped(from, truth), false);
  EXPECT_EQ(S.s, 1.0);
  EXPECT_LT((S.R - truth.R).norm(), 1e-10);
  EXPECT_LT((S.t - truth.t).norm(), 1e-9);
}

TEST(Umeyama, SE3ModeKeepsScaleOneEvenWhenTheDataIsScaled) {
  const std::vector<Vec3> from = randomPoints(30, 3);
  const Similarity S = umeyamaAlignment(from, mapped(from, knownSimilarity(3.0)), false);
  EXPECT_EQ(S.s, 1.0);
  EXPECT_LT((S.R - knownSimilarity(3.0).R).norm(), 1e-9);  // rotation is still found
}

TEST(Umeyama, CoplanarPointsGiveARotationNotAReflection) {
  std::vector<Vec3> from = randomPoints(20, 4);
  for (Vec3& p : from) p.z() = 0;  // rank-2 covariance: the sign fix decides det(R)
  const Similarity truth = knownSimilarity(1.0);
  const Similarity S = umeyamaAlignment(from, mapped(from, truth), false);
  EXPECT_NEAR(S.R.determinant(), 1.0, 1e-12);
  EXPECT_LT((S.R - truth.R).norm(), 1e-9);
}

TEST(Umeyama, CollinearOrSinglePointsAreRejected) {
  std::vector<Vec3> line;
  for (int i = 0; i < 10; ++i) line.emplace_back(i, 2.0 * i, 0.5 * i);
  EXPECT_THROW(umeyamaAlignment(line, line, false), InputError);
  EXPECT_THROW(umeyamaAlignment({Vec3(1, 2, 3)}, {Vec3(1, 2, 3)}, true), InputError);
  EXPECT_THROW(umeyamaAlignment({}, {}, true), InputError);
}

TEST(Umeyama, TransformTrajectoryRotatesOrientationsAndMapsPositions) {
  const Similarity S = knownSimilarity(2.0);
  Trajectory traj{test::pose(0.0, Vec3(1, 0, 0), test::rotZ(0.3))};
  const Trajectory out = transformTrajectory(traj, S);
  EXPECT_LT((out[0].T_w_b.t - (2.0 * S.R * Vec3(1, 0, 0) + S.t)).norm(), 1e-12);
  EXPECT_LT((out[0].T_w_b.R - S.R * test::rotZ(0.3)).norm(), 1e-12);
  EXPECT_EQ(out[0].t, traj[0].t);
}

TEST(AlignMode, ParsesNamesAndRejectsOthers) {
  EXPECT_EQ(parseAlignMode("sim3"), AlignMode::Sim3);
  EXPECT_STREQ(alignModeName(parseAlignMode("se3")), "se3");
  EXPECT_THROW(parseAlignMode("affine"), InputError);
}
