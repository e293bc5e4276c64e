#include <gtest/gtest.h>

#include "eval_test_util.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/eval/trajectory_metrics.hpp"
#include "test_support.hpp"

using namespace mcslam;
using test::pose;

// evo's published figures for this pair (tests/data/eval/tum_fr2_desk/EXPECTED.md, from evo's
// doc/performance.md: `evo_ape tum fr2_desk_groundtruth.txt fr2_desk_ORB.txt --align`). The first file is
// the reference, SE(3) Umeyama, max. time difference 0.01 s (evo's default). evo also printed
// sse 0.143305, i.e. sse / rmse^2 = 2174 pairs.
TEST(ApeFr2Desk, ReproducesEvosPublishedFigures) {
  const Trajectory gt = readTumTrajectory(test::dataPath("eval/tum_fr2_desk/groundtruth.txt"));
  const Trajectory est = readTumTrajectory(test::dataPath("eval/tum_fr2_desk/estimate_orb.txt"));
  ASSERT_EQ(gt.size(), 20957u);
  EvalOptions o;
  o.align = AlignMode::SE3;
  o.max_diff_s = 0.01;
  const ApeResult r = computeApe(gt, est, o);
  EXPECT_EQ(r.stats.count, 2174u);
  EXPECT_NEAR(r.stats.rmse, 0.008119, 1e-5);
  EXPECT_NEAR(r.stats.mean, 0.007492, 1e-5);
  EXPECT_NEAR(r.stats.median, 0.007415, 1e-5);
  EXPECT_NEAR(r.stats.std, 0.003129, 1e-5);
  EXPECT_NEAR(r.stats.min, 0.000350, 1e-5);
  EXPECT_NEAR(r.stats.max, 0.024300, 1e-5);
  EXPECT_NEAR(r.stats.sse, 0.143305, 1e-6);
  // Tighter: each printed figure is evo's value rounded to 6 decimals.
  EXPECT_NEAR(r.stats.rmse, 0.008119, 5e-7);
  EXPECT_NEAR(r.stats.max, 0.024300, 5e-7);
  EXPECT_GT(r.data.ref_path_length, 10.0);
  EXPECT_NEAR(r.rmse_percent, 100.0 * r.stats.rmse / r.data.ref_path_length, 1e-12);
}

namespace {

// A 1 m square walked in 40 steps (4 m of path), 10 Hz.
Trajectory square() {
  Trajectory t;
  for (int i = 0; i <= 40; ++i) {
    const int side = std::min(i / 10, 3), k = i - side * 10;
    const double f = k / 10.0;
    const Vec3 corners[5] = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 0, 1), Vec3(0, 0, 1), Vec3(0, 0, 0)};
    const Vec3 p = corners[side] + f * (corners[side + 1] - corners[side]);
    t.push_back(pose(100.0 + 0.1 * i, p));
  }
  return t;
}

}  // namespace

TEST(Ape, ConstantOffsetWithoutAlignmentGivesItsLengthAndPercentOfPath) {
  const Trajectory ref = square();
  Trajectory est = ref;
  for (StampedPose& p : est) p.T_w_b.t += Vec3(0.03, 0.04, 0);
  EvalOptions o;
  o.align = AlignMode::None;
  const ApeResult r = computeApe(ref, est, o);
  EXPECT_EQ(r.stats.count, ref.size());
  EXPECT_NEAR(r.stats.rmse, 0.05, 1e-12);
  EXPECT_NEAR(r.stats.std, 0.0, 1e-12);
  EXPECT_NEAR(r.data.ref_path_length, 4.0, 1e-12);
  EXPECT_NEAR(r.rmse_percent, 1.25, 1e-10);
  // SE(3) alignment removes the offset.
  o.align = AlignMode::SE3;
  EXPECT_LT(computeApe(ref, est, o).stats.max, 1e-9);
}

TEST(Ape, Sim3AlignmentRemovesScaleAndReportsIt) {
  const Trajectory ref = square();
  Similarity S;
  S.R = test::rotZ(0.4);
  S.t = Vec3(2, 1, 0);
  S.s = 0.5;  // the estimate is half the size, as a monocular run might be
  const Trajectory est = transformTrajectory(ref, S);
  EvalOptions o;
  o.align = AlignMode::SE3;
  EXPECT_GT(computeApe(ref, est, o).stats.rmse, 0.1);
  o.align = AlignMode::Sim3;
  const ApeResult r = computeApe(ref, est, o);
  EXPECT_LT(r.stats.max, 1e-9);
  EXPECT_NEAR(r.data.alignment.s, 2.0, 1e-9);
}

TEST(Ape, NoCommonTimesIsAClearError) {
  const Trajectory ref = square();
  Trajectory est = ref;
  for (StampedPose& p : est) p.t += 1000000000000LL;  // 1000 s later
  EvalOptions o;
  o.reference_name = "gt.txt";
  o.estimate_name = "est.txt";
  try {
    computeApe(ref, est, o);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("no matching timestamps"), std::string::npos) << msg;
    EXPECT_NE(msg.find("gt.txt"), std::string::npos) << msg;
    EXPECT_NE(msg.find("est.txt"), std::string::npos) << msg;
    EXPECT_NE(msg.find("0.01 s"), std::string::npos) << msg;
  }
}

TEST(Ape, EmptyOrDegenerateInputIsAClearError) {
  EvalOptions o;
  o.estimate_name = "est.txt";
  EXPECT_THROW(computeApe(square(), {}, o), InputError);
  Trajectory line;
  for (int i = 0; i < 5; ++i) line.push_back(pose(i, Vec3(i, 0, 0)));
  try {
    computeApe(line, line, o);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("est.txt"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--align none"), std::string::npos) << e.what();
  }
}
