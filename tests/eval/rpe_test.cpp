#include <gtest/gtest.h>

#include <cmath>

#include "eval_test_util.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/eval/trajectory_metrics.hpp"

using namespace mcslam;
using test::pose;

namespace {

// n poses at 10 Hz, each step the body moves by `step` expressed in its own frame.
Trajectory walk(int n, const SE3& step) {
  Trajectory t;
  SE3 T;
  for (int i = 0; i < n; ++i) {
    t.push_back({fromSeconds(0.1 * i), T});
    T = T * step;
  }
  return t;
}

Trajectory straightLine(int n, double spacing) {
  Trajectory t;
  for (int i = 0; i < n; ++i) t.push_back(pose(0.1 * i, Vec3(spacing * i, 0, 0)));
  return t;
}

}  // namespace

TEST(RpePairs, FramesConsecutiveAndAllPairs) {
  const Trajectory t = straightLine(10, 1.0);
  EXPECT_EQ(rpePairs(t, 3, DeltaUnit::Frames, false, 0.1), (IndexPairs{{0, 3}, {3, 6}, {6, 9}}));
  const IndexPairs all = rpePairs(t, 3, DeltaUnit::Frames, true, 0.1);
  ASSERT_EQ(all.size(), 7u);
  EXPECT_EQ(all.front(), std::make_pair(std::size_t{0}, std::size_t{3}));
  EXPECT_EQ(all.back(), std::make_pair(std::size_t{6}, std::size_t{9}));
}

TEST(RpePairs, MetresFollowTheTravelledPathLikeEvo) {
  const Trajectory t = straightLine(21, 0.25);  // binary-exact steps: 1 m every 4 poses
  // The first kept index is where the path first reaches delta, not pose 0 (evo's filter_pairs_by_path).
  EXPECT_EQ(rpePairs(t, 1.0, DeltaUnit::Meters, false, 0.1), (IndexPairs{{4, 8}, {8, 12}, {12, 16}, {16, 20}}));
  const IndexPairs all = rpePairs(t, 1.0, DeltaUnit::Meters, true, 0.1);
  ASSERT_EQ(all.size(), 17u);  // every i with i + 4 <= 20
  for (std::size_t k = 0; k < all.size(); ++k) EXPECT_EQ(all[k], std::make_pair(k, k + 4));
  // A delta between poses is matched to the nearest within the tolerance only.
  EXPECT_TRUE(rpePairs(t, 1.125, DeltaUnit::Meters, true, 0.05).empty());
  EXPECT_EQ(rpePairs(t, 1.125, DeltaUnit::Meters, true, 0.15).size(), 17u);
}

TEST(RpePairs, RejectsBadDeltas) {
  const Trajectory t = straightLine(5, 1.0);
  EXPECT_THROW(rpePairs(t, 0, DeltaUnit::Frames, false, 0.1), InputError);
  EXPECT_THROW(rpePairs(t, 1.5, DeltaUnit::Frames, false, 0.1), InputError);
  EXPECT_THROW(rpePairs(t, -1, DeltaUnit::Meters, false, 0.1), InputError);
}

// Reference: 1 m forward per frame. Estimate: 1 m forward and 1 degree of yaw per frame.
// Per frame E = [I|(1,0,0)]^-1 [Rz(1deg)|(1,0,0)] = [Rz(1deg)|0]: rotation 1 deg, translation 0.
// Over 2 frames the estimate's second step is turned by 1 deg: translation |Rz(1deg)(1,0,0) - (1,0,0)|
// = 2 sin(0.5 deg), rotation 2 deg.
TEST(Rpe, KnownYawDriftGivesTheExpectedErrors) {
  const double deg = M_PI / 180.0;
  const Trajectory ref = walk(11, SE3(Mat3::Identity(), Vec3(1, 0, 0)));
  const Trajectory est = walk(11, SE3(test::rotZ(deg), Vec3(1, 0, 0)));
  RpeOptions o;
  o.eval.align = AlignMode::None;
  o.delta = 1;
  const RpeResult one = computeRpe(ref, est, o);
  ASSERT_EQ(one.pairs.size(), 10u);
  EXPECT_NEAR(one.rotation_deg.mean, 1.0, 1e-9);
  EXPECT_NEAR(one.rotation_deg.std, 0.0, 1e-9);
  EXPECT_NEAR(one.translation.max, 0.0, 1e-12);

  o.delta = 2;
  const RpeResult two = computeRpe(ref, est, o);
  ASSERT_EQ(two.pairs.size(), 5u);
  EXPECT_NEAR(two.rotation_deg.rmse, 2.0, 1e-9);
  EXPECT_NEAR(two.translation.rmse, 2.0 * std::sin(0.5 * deg), 1e-12);
  EXPECT_NEAR(two.translation.min, two.translation.max, 1e-12);
}

TEST(Rpe, ScaleDriftShowsAsTranslationErrorAndSim3RemovesIt) {
  const Trajectory ref = walk(20, SE3(test::rotZ(0.1), Vec3(1, 0, 0)));
  const Trajectory est = walk(20, SE3(test::rotZ(0.1), Vec3(1.1, 0, 0)));
  RpeOptions o;
  o.eval.align = AlignMode::SE3;  // SE(3) alignment leaves relative poses unchanged
  const RpeResult r = computeRpe(ref, est, o);
  EXPECT_NEAR(r.translation.mean, 0.1, 1e-9);
  EXPECT_NEAR(r.rotation_deg.max, 0.0, 1e-6);
  o.eval.align = AlignMode::Sim3;
  const RpeResult s = computeRpe(ref, est, o);
  EXPECT_NEAR(s.data.alignment.s, 1.0 / 1.1, 1e-9);
  EXPECT_LT(s.translation.max, 1e-9);
}

TEST(Rpe, PairsCanComeFromTheReferencePath) {
  // The estimate stands still, so pairing on its path in metres finds nothing; the reference's path works.
  const Trajectory ref = straightLine(9, 0.5);
  Trajectory est = ref;
  for (StampedPose& p : est) p.T_w_b.t = Vec3::Zero();
  RpeOptions o;
  o.eval.align = AlignMode::None;
  o.delta = 1.0;
  o.unit = DeltaUnit::Meters;
  o.eval.estimate_name = "est.txt";
  try {
    computeRpe(ref, est, o);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("gives no pair"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("est.txt"), std::string::npos) << e.what();
  }
  o.pairs_from_reference = true;
  const RpeResult r = computeRpe(ref, est, o);
  EXPECT_EQ(r.pairs, (IndexPairs{{2, 4}, {4, 6}, {6, 8}}));
  EXPECT_NEAR(r.translation.mean, 1.0, 1e-12);  // the estimate missed each 1 m step entirely
}
