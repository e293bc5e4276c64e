// The loop correction on its own thread: the map takes the pose graph's solution at a frame boundary; keyframes
// made during the solve move with their segment, a segment begun during it moves with the one it continues; a
// segment moved during the solve makes the solution stale; without waiting, the solution is taken once ready; a
// correction allocates nothing after the first, on either thread. In a map whose unit drifts (one camera), the
// Sim(3) correction takes the drift of the unit out too: keyframes, their points and the segment's odometry unit.
// In a metric map whose unit was uncertain for a stretch (a rig without overlap before its scale converged), the
// rigid correction stretches that stretch instead of bending the rest. Rotations stay orthonormal over many
// corrections. A loop within a segment the odometry rescaled takes the segment's new unit.
#include <gtest/gtest.h>

#include <cmath>
#include <thread>
#include <vector>

#include "../odometry/synthetic_sequence.hpp"
#include "alloc_testing.hpp"
#include "mcslam/core/binary_io.hpp"
#include "mcslam/places/loop_closer.hpp"
#include "mcslam/places/loop_correction.hpp"

namespace mcslam {
namespace {

SE3 poseAt(double angle_rad, double radius) {
  return {so3Exp(Vec3(0, 0, angle_rad + M_PI / 2)),
          Vec3(radius * std::cos(angle_rad), radius * std::sin(angle_rad), 0)};
}

// A circle of `n` keyframes, as a drifting odometry chains them (a yaw error per step), in one segment whose
// odometry frame is the world's; and the loop the last keyframe closes onto the first.
struct DriftedLoop {
  PlaceMap map{128, 1};
  int32_t segment = -1;
  std::vector<SE3> truth;
  LoopEdge loop;
};

DriftedLoop driftedLoop(int n) {
  DriftedLoop d;
  d.segment = d.map.createSegment(SE3());
  const SE3 drift(so3Exp(Vec3(0, 0, 0.01)), Vec3::Zero());
  SE3 chained = poseAt(0, 10);
  for (int i = 0; i < n; ++i) {
    d.truth.push_back(poseAt(2 * M_PI * i / n, 10));
    if (i > 0) chained = chained * drift * (d.truth[i - 1].inverse() * d.truth[i]);
    d.map.createKeyframe(d.segment, i, static_cast<uint64_t>(i), chained, chained);
  }
  d.loop = {d.map.keyframe(0).id, d.map.keyframe(n - 1).id, d.truth[0].inverse() * d.truth[n - 1],
            Vec6::Constant(0.01)};
  return d;
}

const std::vector<int32_t> kOwnRoots = {0, 1, 2, 3};

TEST(LoopCorrection, TheMapTakesTheSolutionAndItsFrameFollowsTheNewestKeyframe) {
  DriftedLoop d = driftedLoop(40);
  const double error_before = (d.map.keyframe(39).T_w_k.t - d.truth[39].t).norm();
  LoopCorrection correction(64, 4);
  correction.start(d.map, {&d.loop, 1}, kOwnRoots);
  EXPECT_EQ(correction.take(d.map, /*wait=*/true), LoopCorrection::Outcome::Applied);
  EXPECT_FALSE(correction.running());
  EXPECT_LT((d.map.keyframe(39).T_w_k.t - d.truth[39].t).norm(), 0.1 * error_before);
  EXPECT_EQ(d.map.keyframe(0).T_w_k.t, d.truth[0].t);  // the oldest keyframe holds the gauge
  const SE3 T_w_o = d.map.keyframe(39).T_w_k * d.map.keyframe(39).T_o_k.inverse();
  EXPECT_LT((d.map.segmentPose(d.segment).t - T_w_o.t).norm(), 1e-9);
  EXPECT_EQ(correction.take(d.map, true), LoopCorrection::Outcome::None);  // taken once
}

TEST(LoopCorrection, WhatWasMadeDuringTheSolveMovesWithItsSegment) {
  DriftedLoop d = driftedLoop(40);
  LoopCorrection correction(64, 4);
  correction.start(d.map, {&d.loop, 1}, kOwnRoots);
  // During the solve the odometry goes on: two keyframes through the segment's (old) frame, then a loss and a new
  // segment continuing it, with a keyframe of its own.
  const SE3 step(Mat3::Identity(), Vec3(0.5, 0, 0));
  const SE3 T_o_a = d.map.keyframe(39).T_o_k * step, T_o_b = T_o_a * step;
  const int a = d.map.createKeyframe(d.segment, 40, 40, d.map.segmentPose(d.segment) * T_o_a, T_o_a);
  const int b = d.map.createKeyframe(d.segment, 41, 41, d.map.segmentPose(d.segment) * T_o_b, T_o_b);
  const int32_t next = d.map.createSegment(d.map.segmentPose(d.segment), true, d.segment);
  const int c = d.map.createKeyframe(next, 42, 42, d.map.segmentPose(next) * T_o_b, T_o_b);
  ASSERT_EQ(correction.take(d.map, true), LoopCorrection::Outcome::Applied);
  const SE3& T_w_o = d.map.segmentPose(d.segment);
  EXPECT_LT((d.map.keyframe(a).T_w_k.t - (T_w_o * T_o_a).t).norm(), 1e-9);
  EXPECT_LT((d.map.keyframe(b).T_w_k.t - (T_w_o * T_o_b).t).norm(), 1e-9);
  EXPECT_LT((d.map.segmentPose(next).t - T_w_o.t).norm(), 1e-9);
  EXPECT_LT((d.map.keyframe(c).T_w_k.t - d.map.keyframe(b).T_w_k.t).norm(), 1e-9);
  // ... which is where the keyframe newest in the graph now is, as the odometry measured them from it.
  EXPECT_LT((d.map.keyframe(b).T_w_k.t - (d.map.keyframe(39).T_w_k * step * step).t).norm(), 1e-9);
}

// A reused segment (PlaceMap::reuseSegment) may continue one numbered after it: with no keyframe of its own in the
// graph it still moves with the segment up its chain that has one.
TEST(LoopCorrection, ASegmentWithoutKeyframesMovesWithTheSegmentItContinuesWhateverTheirNumbers) {
  DriftedLoop d = driftedLoop(40);
  const int32_t reused = d.map.createSegment(SE3());  // to be set up anew below
  const int32_t later = d.map.createSegment(d.map.segmentPose(d.segment), true, d.segment);
  d.map.reuseSegment(reused, d.map.segmentPose(later), true, later);
  const std::vector<int32_t> roots = {0, 1, 2};
  LoopCorrection correction(64, 4);
  correction.start(d.map, {&d.loop, 1}, roots);
  ASSERT_EQ(correction.take(d.map, true), LoopCorrection::Outcome::Applied);
  const SE3& moved = d.map.segmentPose(d.segment);
  EXPECT_GT(moved.t.norm(), 0.01);  // the loop moved the segment's frame
  EXPECT_LT((d.map.segmentPose(later).t - moved.t).norm(), 1e-9);
  EXPECT_LT((d.map.segmentPose(reused).t - moved.t).norm(), 1e-9);
  EXPECT_LT(rotationAngle(d.map.segmentPose(reused).R, moved.R), 1e-9);
}

TEST(LoopCorrection, ASegmentMovedDuringTheSolveMakesItStale) {
  DriftedLoop d = driftedLoop(40);
  const SE3 before = d.map.keyframe(20).T_w_k;
  LoopCorrection correction(64, 4);
  correction.start(d.map, {&d.loop, 1}, kOwnRoots);
  d.map.moveSegment(d.segment, SE3(Mat3::Identity(), Vec3(0, 0, 1)));
  EXPECT_EQ(correction.take(d.map, true), LoopCorrection::Outcome::Stale);
  EXPECT_EQ(d.map.keyframe(20).T_w_k.t, before.t + Vec3(0, 0, 1));  // as moved, not as solved
  correction.start(d.map, {&d.loop, 1}, kOwnRoots);                 // again, from the map as it is now
  EXPECT_EQ(correction.take(d.map, true), LoopCorrection::Outcome::Applied);
}

TEST(LoopCorrection, WithoutWaitingTheSolutionIsTakenOnceReady) {
  DriftedLoop d = driftedLoop(40);
  LoopCorrection correction(64, 4);
  correction.start(d.map, {&d.loop, 1}, kOwnRoots);
  LoopCorrection::Outcome outcome = LoopCorrection::Outcome::None;
  int calls = 0;
  while ((outcome = correction.take(d.map, /*wait=*/false)) == LoopCorrection::Outcome::None) {
    ++calls;
    std::this_thread::yield();
  }
  EXPECT_EQ(outcome, LoopCorrection::Outcome::Applied);
  EXPECT_LT((d.map.keyframe(39).T_w_k.t - d.truth[39].t).norm(), 0.1);
  EXPECT_FALSE(correction.running());
  (void)calls;  // how many frames it took depends on the machine
}

TEST(LoopCorrection, AfterTheFirstACorrectionAllocatesNothingOnEitherThread) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  DriftedLoop d = driftedLoop(40);
  LoopCorrection correction(64, 4);
  correction.start(d.map, {&d.loop, 1}, kOwnRoots);
  ASSERT_EQ(correction.take(d.map, true), LoopCorrection::Outcome::Applied);
  const uint64_t solver_before = correction.threadAllocations();
  alloc::ThreadScope scope;
  const SE3 step(Mat3::Identity(), Vec3(0.5, 0, 0));
  d.map.createKeyframe(d.segment, 40, 40, d.map.segmentPose(d.segment) * step, step);  // the graph grows
  correction.start(d.map, {&d.loop, 1}, kOwnRoots);
  ASSERT_EQ(correction.take(d.map, true), LoopCorrection::Outcome::Applied);
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_EQ(correction.threadAllocations() - solver_before, 0u);
}

// One camera around the circle: its unit grows by 1% per keyframe (a metre near keyframe i measures 1.01^i
// odometry units), and each keyframe holds a point 5 m ahead, in its own unit. The last keyframe sees the first
// again: the loop measures where, and that its unit is 1.01^39 times the first's.
struct MonocularLoop {
  PlaceMap map{64, 1};
  int32_t segment = -1;
  std::vector<SE3> truth;
  std::vector<double> unit;  // odometry units per metre at each keyframe
  LoopEdge loop;
};

MonocularLoop monocularLoop(int n) {
  MonocularLoop d;
  d.segment = d.map.createSegment(SE3());
  SE3 chained = poseAt(0, 10);
  for (int i = 0; i < n; ++i) {
    d.truth.push_back(poseAt(2 * M_PI * i / n, 10));
    d.unit.push_back(std::pow(1.01, i));
    if (i > 0) {
      SE3 step = d.truth[i - 1].inverse() * d.truth[i];
      step.t *= d.unit[i - 1];
      chained = chained * step;
    }
    const int slot = d.map.createKeyframe(d.segment, i, static_cast<uint64_t>(i), chained, chained);
    PlacePoint p;
    p.p_k = Eigen::Vector3f(0, 0, static_cast<float>(5 * d.unit[i]));
    p.cam = 0;
    d.map.addPoint(slot, p);
    d.map.finishKeyframe(slot);
  }
  d.loop = {d.map.keyframe(0).id, d.map.keyframe(n - 1).id, d.truth[0].inverse() * d.truth[n - 1],
            Vec6::Constant(0.01), 1.0 / d.unit[n - 1],      0.005};
  return d;
}

TEST(LoopCorrection, AMonocularLoopTakesTheDriftOfTheUnitOut) {
  MonocularLoop d = monocularLoop(40);
  const double error_before = (d.map.keyframe(39).T_w_k.t - d.truth[39].t).norm();
  LoopCorrection correction(64, 4, /*similarity=*/true);
  ASSERT_TRUE(correction.similarity());
  correction.start(d.map, {&d.loop, 1}, kOwnRoots);
  ASSERT_EQ(correction.take(d.map, /*wait=*/true), LoopCorrection::Outcome::Applied);
  double worst = 0;
  for (int i = 0; i < 40; ++i) worst = std::max(worst, (d.map.keyframe(i).T_w_k.t - d.truth[i].t).norm());
  EXPECT_GT(error_before, 3.0);
  EXPECT_LT(worst, 0.1 * error_before);
  // Each keyframe's point is back at 5 m, and its unit says how the odometry's relates to the world's.
  for (int i = 0; i < 40; i += 13) {
    EXPECT_NEAR(d.map.points(i)[0].p_k.z(), 5.0, 0.25) << "keyframe " << i;
    EXPECT_NEAR(d.map.keyframe(i).unit * d.unit[i], 1.0, 0.05) << "keyframe " << i;
  }
  // The odometry goes on in its own unit: the segment's frame puts its newest pose where the graph put that
  // keyframe, at the unit the graph found there.
  EXPECT_NEAR(d.map.segmentScale(d.segment) * d.unit[39], 1.0, 0.05);
  const SE3 newest = d.map.toWorld(d.segment, d.map.keyframe(39).T_o_k);
  EXPECT_LT((newest.t - d.map.keyframe(39).T_w_k.t).norm(), 1e-9);
  EXPECT_LT(rotationAngle(newest.R, d.map.keyframe(39).T_w_k.R), 1e-9);
}

TEST(LoopCorrection, ARigidCorrectionCannotUndoADriftOfTheUnit) {
  MonocularLoop similar = monocularLoop(40), rigid = monocularLoop(40);
  LoopCorrection by_similarity(64, 4, true), by_rigid_motion(64, 4, false);
  by_similarity.start(similar.map, {&similar.loop, 1}, kOwnRoots);
  by_rigid_motion.start(rigid.map, {&rigid.loop, 1}, kOwnRoots);
  ASSERT_EQ(by_similarity.take(similar.map, true), LoopCorrection::Outcome::Applied);
  ASSERT_EQ(by_rigid_motion.take(rigid.map, true), LoopCorrection::Outcome::Applied);
  double similar_error = 0, rigid_error = 0;
  for (int i = 0; i < 40; ++i) {
    similar_error += (similar.map.keyframe(i).T_w_k.t - similar.truth[i].t).norm();
    rigid_error += (rigid.map.keyframe(i).T_w_k.t - rigid.truth[i].t).norm();
  }
  EXPECT_LT(similar_error, 0.25 * rigid_error);
  EXPECT_EQ(rigid.map.segmentScale(rigid.segment), 1.0);
}

// The loop is kept in the keyframes' odometry units: solving the map again with the same loop, after its first
// correction changed the keyframes' units, finds the map as it is (it once applied the loop's scale again).
TEST(LoopCorrection, ASecondSolveDoesNotApplyASimilarityLoopAgain) {
  MonocularLoop d = monocularLoop(40);
  LoopCorrection correction(64, 4, /*similarity=*/true);
  correction.start(d.map, {&d.loop, 1}, kOwnRoots);
  ASSERT_EQ(correction.take(d.map, true), LoopCorrection::Outcome::Applied);
  const double scale = d.map.segmentScale(d.segment);
  const SE3 newest = d.map.keyframe(39).T_w_k;
  correction.start(d.map, {&d.loop, 1}, kOwnRoots);
  ASSERT_EQ(correction.take(d.map, true), LoopCorrection::Outcome::Applied);
  EXPECT_NEAR(d.map.segmentScale(d.segment) / scale, 1.0, 0.01);
  EXPECT_LT((d.map.keyframe(39).T_w_k.t - newest.t).norm(), 0.05);
}

// A circle of `n` keyframes whose odometry measured keyframes 1 to `short_end` at 0.7 of their length (the unit a rig
// without overlap had before it converged), the rest right. Each keyframe looks 60 degrees off its direction of
// travel, turning by a further degree per keyframe, so that the length's direction is the same in no two frames.
struct ShortStretch {
  PlaceMap map{64, 1};
  int32_t segment = -1;
  std::vector<SE3> truth;
  LoopEdge loop;
};

ShortStretch shortStretch(int n, int short_end, double unit_sigma) {
  ShortStretch d;
  d.segment = d.map.createSegment(SE3());
  SE3 chained;
  for (int i = 0; i < n; ++i) {
    SE3 T = poseAt(2 * M_PI * i / n, 10);
    T.R = T.R * so3Exp(Vec3(0, 0, (60.0 + i) * M_PI / 180));
    d.truth.push_back(T);
    if (i == 0) chained = T;
    const bool short_step = i >= 1 && i <= short_end;
    if (i > 0) {
      SE3 step = d.truth[i - 1].inverse() * d.truth[i];
      if (short_step) step.t *= 0.7;
      chained = chained * step;
    }
    const int slot = d.map.createKeyframe(d.segment, i, static_cast<uint64_t>(i), chained, chained);
    d.map.setUnitSigma(slot, short_step ? unit_sigma : 0.0);
  }
  d.loop = {d.map.keyframe(0).id, d.map.keyframe(n - 1).id, d.truth[0].inverse() * d.truth[n - 1],
            Vec6::Constant(0.01)};
  return d;
}

double worstPositionError(const ShortStretch& d) {
  double worst = 0;
  for (int i = 0; i < static_cast<int>(d.truth.size()); ++i)
    worst = std::max(worst, (d.map.keyframe(i).T_w_k.t - d.truth[static_cast<std::size_t>(i)].t).norm());
  return worst;
}

TEST(LoopCorrection, AStretchWhoseUnitWasUncertainTakesTheCorrectionInItsLength) {
  ShortStretch known = shortStretch(40, 12, 0.0), uncertain = shortStretch(40, 12, 0.5);
  const double before = worstPositionError(uncertain);
  LoopCorrection by_known(64, 4), by_uncertain(64, 4);
  by_known.start(known.map, {&known.loop, 1}, kOwnRoots);
  by_uncertain.start(uncertain.map, {&uncertain.loop, 1}, kOwnRoots);
  ASSERT_EQ(by_known.take(known.map, true), LoopCorrection::Outcome::Applied);
  ASSERT_EQ(by_uncertain.take(uncertain.map, true), LoopCorrection::Outcome::Applied);
  EXPECT_GT(before, 2.0);
  // Told nothing, the graph bends the whole circle (4.4 m off at worst); told which lengths were uncertain, it
  // lengthens them. Not each by 1/0.7: one loop says how much longer the stretch is along two directions, and
  // independent lengths share that unevenly (0.23 m off at worst).
  EXPECT_GT(worstPositionError(known), 2.0);
  EXPECT_LT(worstPositionError(uncertain), 0.1 * worstPositionError(known));
  EXPECT_LT(worstPositionError(uncertain), 0.3);
}

double orthonormalityError(const Mat3& R) { return (R.transpose() * R - Mat3::Identity()).norm(); }

// Each correction composes the segment's frame with the last; the odometry's next keyframe is placed through that
// frame and becomes the next solve's newest node: a rounding error of the rotation would double with each.
TEST(LoopCorrection, RotationsStayOrthonormalOverManyCorrections) {
  DriftedLoop d = driftedLoop(40);
  ASSERT_GE(d.map.capacity(), 100);
  LoopCorrection correction(128, 4);
  SE3 T_o_newest = d.map.keyframe(39).T_o_k;
  const SE3 step(so3Exp(Vec3(0.01, 0.02, 0.3)), Vec3(0.4, 0.1, 0));
  double worst = 0;
  for (int i = 0; i < 60; ++i) {
    T_o_newest = T_o_newest * step;
    ASSERT_GE(d.map.createKeyframe(d.segment, 40 + i, 40 + static_cast<uint64_t>(i),
                                   d.map.toWorld(d.segment, T_o_newest), T_o_newest),
              0);
    correction.start(d.map, {&d.loop, 1}, kOwnRoots);
    ASSERT_EQ(correction.take(d.map, /*wait=*/true), LoopCorrection::Outcome::Applied);
    worst = std::max(worst, orthonormalityError(d.map.segmentPose(d.segment).R));
    for (int slot = 0; slot < d.map.capacity(); ++slot)
      if (d.map.keyframe(slot).alive) worst = std::max(worst, orthonormalityError(d.map.keyframe(slot).T_w_k.R));
  }
  EXPECT_LT(worst, 1e-12);
}

// Before its unit converged, a rig without overlap rescales the whole of its segment when the estimate moves: a
// loop within the segment was measured in the unit the keyframes had and takes the new one; a loop onto another
// segment's keyframe spans two units and stays as measured.
TEST(LoopCorrection, ALoopWithinARescaledSegmentTakesItsUnit) {
  DriftedLoop d = driftedLoop(40);
  const int32_t other = d.map.createSegment(SE3());
  const int slot = d.map.createKeyframe(other, 100, 100, d.truth[5], d.truth[5]);
  const LoopEdge across{d.map.keyframe(slot).id, d.map.keyframe(39).id,
                        d.map.keyframe(slot).T_w_k.inverse() * d.map.keyframe(39).T_w_k, Vec6::Constant(0.01)};
  const LoopEdge loops[] = {d.loop, across};
  std::string bytes;
  ByteWriter out(bytes);
  putLoops(out, loops, {kOwnRoots.data(), 2});
  const Rig rig = test::nonOverlappingRig3();
  LoopCloser closer(rig, PlacesOptions{}, 1.2f, 64, /*similarity=*/false);
  ByteReader in(bytes, "loops");
  closer.read(in, 2);
  const std::vector<Vec3> centers = rig.cameraCenters();
  const SE3 before = d.map.keyframe(0).T_w_k.inverse() * d.map.keyframe(39).T_w_k;
  d.map.rescaleSegment(d.segment, 2.0, Vec3::Zero(), /*from_frame=*/0, centers);
  closer.followRescale(d.map, d.segment, 2.0, /*from_frame=*/0);
  ASSERT_EQ(closer.loopEdges().size(), 2u);
  EXPECT_LT((closer.loopEdges()[0].T_a_b.t - 2.0 * d.loop.T_a_b.t).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(closer.loopEdges()[0].sigma[0], 0.02);
  EXPECT_DOUBLE_EQ(closer.loopEdges()[0].sigma[3], 0.01);  // rotations have no unit
  EXPECT_LT((closer.loopEdges()[1].T_a_b.t - across.T_a_b.t).norm(), 1e-12);
  // The map stretched the segment alike: the loop and its keyframes are in one unit again.
  const SE3 now = d.map.keyframe(0).T_w_k.inverse() * d.map.keyframe(39).T_w_k;
  EXPECT_NEAR(now.t.norm() / before.t.norm(), closer.loopEdges()[0].T_a_b.t.norm() / d.loop.T_a_b.t.norm(), 1e-9);
}

}  // namespace
}  // namespace mcslam
