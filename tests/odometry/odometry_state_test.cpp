// The odometry's state and its owners: the rig state a consumer receives by value, the map's landmark ids, the
// tracker's per-landmark counts.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <vector>

#include "alloc_testing.hpp"
#include "mcslam/core/alloc_counter.hpp"
#include "mcslam/odometry/landmark_tracks.hpp"
#include "mcslam/odometry/loss_clock.hpp"
#include "mcslam/odometry/map.hpp"
#include "mcslam/odometry/odometry.hpp"
#include "mcslam/odometry/rig_state.hpp"
#include "mcslam/odometry/scale_estimator.hpp"
#include "mcslam/odometry/scale_supervisor.hpp"
#include "mcslam/odometry/window_bridge.hpp"
#include "synthetic_sequence.hpp"

using namespace mcslam;

namespace {

SE3 shifted(const SE3& T, double dx) { return SE3(T.R, T.t + Vec3(dx, 0, 0)); }

}  // namespace

TEST(RigState, StartsAtTheCalibrationWithVersionZero) {
  const Rig rig = test::isecRig();
  const RigState s(rig);
  EXPECT_EQ(s.version(), 0u);
  ASSERT_EQ(s.cameras(), rig.size());
  for (int c = 0; c < rig.size(); ++c) {
    EXPECT_EQ(s.T_b_c(c).t, rig.T_b_c(c).t);
    EXPECT_FALSE(s.reestimated(c));
  }
  EXPECT_EQ(s.scale(), ScaleStatus::Metric);
  Rig one;
  one.cameras.push_back(rig.cameras[0]);
  EXPECT_EQ(RigState(one).scale(), ScaleStatus::Monocular);
  EXPECT_FALSE(RigState(one).metric());
  EXPECT_TRUE(RigState(one).scaleConverged());
}

TEST(RigState, TheVersionMovesExactlyWhenAValueChanges) {
  const Rig rig = test::isecRig();
  RigState s(rig);
  s.setExtrinsic(2, rig.T_b_c(2));  // the same value
  EXPECT_EQ(s.version(), 0u);
  s.setExtrinsic(2, shifted(rig.T_b_c(2), 0.01));
  EXPECT_EQ(s.version(), 1u);
  s.setExtrinsic(2, shifted(rig.T_b_c(2), 0.01));
  EXPECT_EQ(s.version(), 1u);
  s.markReestimated(2);
  EXPECT_EQ(s.version(), 2u);
  s.markReestimated(2);
  EXPECT_EQ(s.version(), 2u);
  s.setScale(ScaleStatus::Metric);
  EXPECT_EQ(s.version(), 2u);
  s.setScale(ScaleStatus::Unscaled);
  EXPECT_EQ(s.version(), 3u);
  EXPECT_FALSE(s.scaleConverged());
  EXPECT_FALSE(s.metric());
  s.setScale(ScaleStatus::Metric);
  EXPECT_EQ(s.version(), 4u);
  EXPECT_TRUE(s.reestimated(2));
  EXPECT_FALSE(s.reestimated(1));
}

TEST(RigState, AConsumerKeepsTheValuesItReceivedUntilItFollowsAgain) {
  const Rig rig = test::isecRig();
  RigState producer(rig), consumer(rig);
  EXPECT_FALSE(consumer.follow(producer));  // same version: nothing to take
  producer.setExtrinsic(1, shifted(rig.T_b_c(1), 0.02));
  producer.markReestimated(1);
  EXPECT_TRUE(consumer.follow(producer));
  EXPECT_EQ(consumer.version(), producer.version());
  EXPECT_EQ(consumer.T_b_c(1).t, producer.T_b_c(1).t);
  EXPECT_TRUE(consumer.reestimated(1));
  // The producer moves on; the consumer's copy does not.
  producer.setExtrinsic(1, shifted(rig.T_b_c(1), 0.05));
  producer.setScale(ScaleStatus::Unscaled);
  EXPECT_DOUBLE_EQ(consumer.T_b_c(1).t.x(), rig.T_b_c(1).t.x() + 0.02);
  EXPECT_EQ(consumer.scale(), ScaleStatus::Metric);
  EXPECT_NE(consumer.version(), producer.version());
}

TEST(RigState, FollowingAllocatesNothing) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  const Rig rig = test::isecRig();
  RigState producer(rig), consumer(rig);
  alloc::ThreadScope scope;
  for (int i = 0; i < 10; ++i) {
    producer.setExtrinsic(i % rig.size(), shifted(rig.T_b_c(i % rig.size()), 0.001 * (i + 1)));
    consumer.follow(producer);
  }
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_EQ(consumer.version(), producer.version());
}

TEST(MapIds, LandmarkIdsAreUniqueOverTheRunAndStableAcrossSlotReuse) {
  const Rig rig = test::isecRig();
  Map map(rig, 10, 4, 8);
  std::set<int64_t> ids;
  std::vector<int> slots;
  for (int i = 0; i < 8; ++i) {
    const int s = map.createLandmark(Vec3(i, 0, 1), Descriptor{}, 0);
    ASSERT_GE(s, 0);
    slots.push_back(s);
    EXPECT_TRUE(ids.insert(map.landmark(s).id).second);
  }
  EXPECT_EQ(map.createLandmark(Vec3::Zero(), Descriptor{}, 0), -1);  // full
  const int64_t kept_id = map.landmark(slots[5]).id;
  // Erase and create again, many times: slots are reused, ids never.
  for (int round = 0; round < 50; ++round) {
    const int victim = slots[round % 4];
    const int64_t old_id = map.landmark(victim).id;
    map.eraseLandmark(victim);
    EXPECT_EQ(map.landmarkSlotOf(old_id), -1);
    const int s = map.createLandmark(Vec3(round, 1, 1), Descriptor{}, 0);
    ASSERT_EQ(s, victim);  // the only free slot
    EXPECT_TRUE(ids.insert(map.landmark(s).id).second);
    EXPECT_EQ(map.landmarkSlotOf(map.landmark(s).id), s);
  }
  EXPECT_EQ(map.landmark(slots[5]).id, kept_id);  // a landmark keeps its id while others come and go
  EXPECT_EQ(map.landmarkSlotOf(kept_id), slots[5]);
  for (int i = 0; i < 8; ++i) EXPECT_EQ(map.landmarkSlotOf(map.landmark(slots[i]).id), slots[i]);
  // A new map after clear() goes on with new ids.
  map.clear();
  for (const int64_t id : ids) EXPECT_EQ(map.landmarkSlotOf(id), -1);
  const int s = map.createLandmark(Vec3::Zero(), Descriptor{}, 0);
  EXPECT_TRUE(ids.insert(map.landmark(s).id).second);
}

TEST(LandmarkTracks, AReusedSlotStartsFromFreshCounts) {
  const Rig rig = test::isecRig();
  Map map(rig, 10, 4, 2);
  LandmarkTracks tracks(2);
  const int a = map.createLandmark(Vec3::Zero(), Descriptor{}, 0);
  tracks.of(map, a).visible = 9;
  tracks.of(map, a).found = 4;
  EXPECT_EQ(tracks.peek(map, a).visible, 9u);
  EXPECT_EQ(tracks.of(map, a).found, 4u);
  map.eraseLandmark(a);
  const int b = map.createLandmark(Vec3::Ones(), Descriptor{}, 0);
  ASSERT_EQ(b, a);
  EXPECT_EQ(tracks.peek(map, b).visible, 0u);  // read-only: fresh, and the slot is left as it was
  LandmarkTrack& t = tracks.of(map, b);
  EXPECT_EQ(t.visible, 0u);
  EXPECT_EQ(t.found, 0u);
  EXPECT_EQ(t.matched_frame, ~0ull);
  EXPECT_EQ(t.id, map.landmark(b).id);
}

TEST(ScaleSupervisor, AMetricMapIsNeverRescaled) {
  const Rig rig = test::nonOverlappingRig3();
  OdometryOptions options;
  Map map(rig, 100, options.max_keyframes, 100);
  ScaleSupervisor supervisor(rig, options, 100);
  supervisor.start(false);
  OdometryStats stats;
  const RigState state(rig);
  supervisor.startEstimate(map, state, 10.0, 7);
  const ScaleSupervisor::Rescale r = supervisor.takeEstimate(map, state, 9, stats);
  EXPECT_FALSE(r.apply);
  EXPECT_EQ(stats.scale_estimates, 0u);
}

// What the loop closer is told of the unit: nothing uncertain for a rig whose maps start metric; for a rig that
// started a map up to scale, unknown before any estimate; and, for a map it then started metric (from a place
// map's points after a loss), the drift per keyframe: nothing follows that map's unit.
TEST(ScaleSupervisor, TheUnitSigmaSaysWhatFollowsTheUnit) {
  const Rig rig = test::nonOverlappingRig3();
  OdometryOptions options;
  ScaleSupervisor supervisor(rig, options, 100);
  supervisor.start(false);
  EXPECT_EQ(supervisor.unitSigma(5), 0.0);
  supervisor.start(true);
  EXPECT_EQ(supervisor.unitSigma(5), 1.0);
  supervisor.start(false);
  EXPECT_EQ(supervisor.unitSigma(5), options.scale_drift_per_keyframe);
  ScaleSupervisor one_camera(test::isecRig().subset({2}), options, 100);
  one_camera.start(true);
  EXPECT_EQ(one_camera.unitSigma(5), 0.0);
}

// The combined estimate's sigma grows with the drift from its last window to the keyframe asked about.
TEST(ScaleFilter, TheSigmaGrowsWithTheDriftSinceTheLastWindow) {
  ScaleFilter filter;
  EXPECT_EQ(filter.sigmaAt(10), INFINITY);
  filter.setDrift(0.01);
  ASSERT_TRUE(filter.add(0.0, 0.02, 0, 10, 0.0));
  EXPECT_NEAR(filter.sigmaAt(10), 0.02, 1e-12);
  EXPECT_NEAR(filter.sigmaAt(5), 0.02, 1e-12);
  EXPECT_NEAR(filter.sigmaAt(26), std::sqrt(0.02 * 0.02 + 16 * 0.01 * 0.01), 1e-12);
}

// The window knows landmarks by their ids, not their slots: after slots were recycled (ids ahead of slots), a solve
// still writes every landmark back to its own slot.
TEST(WindowBridge, SolvesReachLandmarksByIdAfterSlotReuse) {
  const Rig rig = test::nonOverlappingRig3();
  OdometryOptions options;
  options.backend_thread = false;
  constexpr int kLandmarks = 300;
  Map map(rig, 400, options.max_keyframes, kLandmarks);
  for (int round = 0; round < 3; ++round) {  // recycle every slot: ids now run ahead of slots
    for (int i = 0; i < kLandmarks; ++i) map.createLandmark(Vec3::Zero(), Descriptor{}, 0);
    for (int i = 0; i < kLandmarks; ++i) map.eraseLandmark(i);
  }
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<SE3> poses;
  for (int k = 0; k < 3; ++k) {
    poses.emplace_back(Eigen::AngleAxisd(0.1 * k, Vec3::UnitY()).toRotationMatrix(), Vec3(0.1 * k, 0, 0.3 * k));
  }
  std::vector<int> kfs;
  for (int k = 0; k < 3; ++k) {
    const int s = map.createKeyframe();
    map.keyframe(s).T_w_b = poses[k];
    for (int c = 0; c < rig.size(); ++c) map.keyframe(s).features.sets[c].count = 0;
    kfs.push_back(s);
  }
  std::vector<Vec3> truth(kLandmarks);
  for (int i = 0; i < kLandmarks; ++i) {
    const Vec3 p = Vec3(0, 0, 0.5) + (3.0 + u(rng)) * Vec3(u(rng), 0.3 * u(rng), u(rng)).normalized();
    const int lm = map.createLandmark(p + Vec3(0.02, -0.01, 0.015), Descriptor{}, 0);  // off the truth
    ASSERT_GE(lm, 0);
    ASSERT_NE(map.landmark(lm).id, lm);
    truth[lm] = p;
    for (int k = 0; k < 3; ++k) {
      for (int c = 0; c < rig.size(); ++c) {
        const Vec3 p_c = (poses[k] * rig.T_b_c(c)).inverse() * p;
        Vec2 uv;
        if (p_c.z() < 0.3 || !rig.model(c).project(p_c, uv) || !rig.model(c).inImage(uv)) continue;
        FeatureSet& set = map.keyframe(kfs[k]).features.sets[c];
        if (set.count == set.capacity()) continue;
        Keypoint kp;
        kp.x = static_cast<float>(uv.x());
        kp.y = static_cast<float>(uv.y());
        kp.octave = 0;
        set.keypoints[set.count] = kp;
        map.addObservation(lm, kfs[k], c, set.count);
        ++set.count;
      }
    }
  }
  WindowBridge bridge(rig, options, 400);
  for (const int s : kfs) bridge.optimize(map, s);  // the first, alone, has nothing to solve
  EXPECT_EQ(bridge.solves(), 3u);
  int in_window = 0, closer = 0;
  for (int lm = 0; lm < kLandmarks; ++lm) {
    const Landmark& l = map.landmark(lm);
    if (!l.alive || !l.in_backend) continue;
    ++in_window;
    closer += (l.p_w - truth[lm]).norm() < 0.5 * Vec3(0.02, -0.01, 0.015).norm() ? 1 : 0;
  }
  EXPECT_GT(in_window, 40);
  EXPECT_GT(closer, 0.9 * in_window);  // written back to their own slots
}

// A new unit changes how far the rig moved, not where its cameras sit on it: each landmark stays on the ray of the
// newest camera that saw it, at s times the depth, while keyframes scale about the center. Scaling the landmarks
// about the center too would move them off that ray by (s - 1) times the camera's lever arm.
TEST(WindowBridge, ARescaleKeepsEachLandmarkOnItsNewestObserversRay) {
  const Rig rig = test::nonOverlappingRig3();
  OdometryOptions options;
  options.backend_thread = false;
  Map map(rig, 400, options.max_keyframes, 16);
  // Three keyframes turning as they go; each landmark's observations listed oldest, newest, middle.
  const SE3 poses[3] = {SE3(Mat3::Identity(), Vec3(0, 0, 0)),
                        SE3(Eigen::AngleAxisd(0.15, Vec3::UnitY()).toRotationMatrix(), Vec3(0.1, 0, 0.25)),
                        SE3(Eigen::AngleAxisd(0.3, Vec3::UnitY()).toRotationMatrix(), Vec3(0.2, 0, 0.5))};
  int kfs[3] = {};
  for (int k = 0; k < 3; ++k) {
    kfs[k] = map.createKeyframe();
    map.keyframe(kfs[k]).T_w_b = poses[k];
  }
  struct Seen {
    int lm, newest_kf, cam;
  };
  std::vector<Seen> seen;
  for (int c = 0; c < rig.size(); ++c) {
    if (rig.T_b_c(c).t.norm() < 0.05) continue;  // no lever arm to get wrong
    const int lm = map.createLandmark((poses[2] * rig.T_b_c(c)) * Vec3(0.3, -0.2, 4.0), Descriptor{}, 0);
    map.addObservation(lm, kfs[0], c, 0);
    map.addObservation(lm, kfs[2], c, 0);  // the newest by id, neither first nor last
    map.addObservation(lm, kfs[1], c, 0);
    seen.push_back({lm, kfs[2], c});
  }
  ASSERT_GE(seen.size(), 2u);
  std::vector<Vec3> before;
  for (const Seen& x : seen) before.push_back(map.landmark(x.lm).p_w);
  WindowBridge bridge(rig, options, 400);
  const double s = 1.6;
  const Vec3 center(1, 0, -2);
  bridge.rescale(map, s, center);
  EXPECT_TRUE(map.keyframe(kfs[2]).T_w_b.t.isApprox(center + s * (poses[2].t - center)));
  for (std::size_t i = 0; i < seen.size(); ++i) {
    const Vec3 camera_before = (poses[2] * rig.T_b_c(seen[i].cam)).t;
    const Vec3 camera_after = (map.keyframe(seen[i].newest_kf).T_w_b * rig.T_b_c(seen[i].cam)).t;
    const Vec3 expected = camera_after + s * (before[i] - camera_before);
    EXPECT_LT((map.landmark(seen[i].lm).p_w - expected).norm(), 1e-9) << "camera " << seen[i].cam;
  }
}

// The time lost is the frames' own time since the loss began; a camera clock stepped back an hour (or a frame
// delivered twice) neither holds the loss open nor ends it early: such stamps add nothing, and are counted.
TEST(LossClock, AClockSteppedBackDoesNotHoldTheLossOpen) {
  LossClock clock;
  const auto at = [](double s) { return static_cast<Timestamp>(s * 1e9); };
  for (int i = 0; i <= 10; ++i) EXPECT_TRUE(clock.frame(at(3600 + 0.1 * i)));
  clock.startLoss();  // lost from t = 3601 s
  EXPECT_TRUE(clock.frame(at(3601.1)));
  EXPECT_FALSE(clock.frame(at(1.0)));  // the camera's clock stepped back an hour
  EXPECT_FALSE(clock.frame(at(1.0)));  // a frame delivered twice
  for (int i = 1; i <= 29; ++i) EXPECT_TRUE(clock.frame(at(1.0 + 0.1 * i)));
  EXPECT_NEAR(clock.lostSeconds(), 3.0, 1e-6);  // 30 frame periods since the loss began
  EXPECT_EQ(clock.stampsNotIncreasing(), 2u);
  clock.startLoss();
  EXPECT_EQ(clock.lostSeconds(), 0.0);
}
