#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <thread>

#include "alloc_testing.hpp"
#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/alloc_counter.hpp"
#include "mcslam/odometry/odometry.hpp"
#include "mcslam/odometry/scale_estimator.hpp"
#include "mcslam/odometry/scale_supervisor.hpp"
#include "synthetic_sequence.hpp"
#include "test_support.hpp"

using namespace mcslam;

namespace {

// A window of 8 keyframes over 1 m of travel (body: y down, z forward), turning `turn_deg` in all, with
// points 2-6 m around; every keyframe observes every point that projects, with `noise_px`. The map then
// holds the poses and points with positions multiplied by `map_scale` about the first keyframe.
void buildWindow(const Rig& rig, Map& map, double turn_deg, double map_scale, double noise_px) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, noise_px);
  constexpr int kKeyframes = 8;
  std::vector<SE3> poses;
  for (int k = 0; k < kKeyframes; ++k) {
    const double a = turn_deg * M_PI / 180.0 * k / (kKeyframes - 1);
    poses.emplace_back(Eigen::AngleAxisd(a, Vec3::UnitY()).toRotationMatrix(),
                       Vec3(0.05 * k * k / 7.0, 0, 1.0 * k / 7.0));
  }
  std::vector<int> slots;
  for (int k = 0; k < kKeyframes; ++k) {
    const int s = map.createKeyframe();
    Keyframe& kf = map.keyframe(s);
    kf.T_w_b = poses[k];
    kf.T_w_b.t = poses[0].t + map_scale * (poses[k].t - poses[0].t);
    kf.in_backend = true;
    for (int c = 0; c < rig.size(); ++c) kf.features.sets[c].count = 0;
    slots.push_back(s);
  }
  for (int i = 0; i < 1500; ++i) {
    const double r = 2.0 + 2.0 * (u(rng) + 1.0);
    const Vec3 dir = Vec3(u(rng), 0.4 * u(rng), u(rng)).normalized();
    const Vec3 p = Vec3(0, 0, 0.5) + r * dir;
    const int lm = map.createLandmark(poses[0].t + map_scale * (p - poses[0].t), Descriptor{}, 0);
    for (int k = 0; k < kKeyframes; ++k) {
      Keyframe& kf = map.keyframe(slots[k]);
      for (int c = 0; c < rig.size(); ++c) {
        const Vec3 p_c = (poses[k] * rig.T_b_c(c)).inverse() * p;
        Vec2 uv;
        if (p_c.z() < 0.3 || !rig.model(c).project(p_c, uv) || !rig.model(c).inImage(uv)) continue;
        FeatureSet& set = kf.features.sets[c];
        if (set.count == set.capacity()) continue;
        Keypoint kp;
        kp.x = static_cast<float>(uv.x() + noise(rng));
        kp.y = static_cast<float>(uv.y() + noise(rng));
        kp.octave = 0;
        set.keypoints[set.count] = kp;
        map.addObservation(lm, slots[k], c, set.count);
        ++set.count;
      }
    }
  }
}

// A supervisor of a map started up to scale, over a window that turns 60 degrees in a unit 2.5x off.
struct SupervisedWindow {
  explicit SupervisedWindow(const OdometryOptions& options) : supervisor(rig, options, 2000) {
    state.setScale(ScaleStatus::Unscaled);
    buildWindow(rig, map, 60.0, 2.5, 0.5);
    supervisor.start(true);
  }
  const Rig rig = test::nonOverlappingRig3();
  RigState state{rig};
  Map map{rig, 2000, 14, 4000};
  ScaleSupervisor supervisor;
  OdometryStats stats;
};

}  // namespace

// The estimator finds the factor that makes a wrongly scaled window metric when the window turns.
TEST(ScaleEstimator, FindsTheMetricScaleOfATurningWindow) {
  const Rig rig = test::nonOverlappingRig3();
  for (double map_scale : {0.4, 1.0, 2.5}) {
    Map map(rig, 2000, 14, 4000);
    buildWindow(rig, map, 60.0, map_scale, 0.5);
    ScaleEstimator est(rig, 4000, 8 * 3 * 2000, 14, 1.2f, 8);
    const ScaleEstimate e = est.estimate(map, 30.0);
    std::printf("map scale %.2f: estimate %.4f (expected %.4f), sigma %.4f, %d landmarks, chi2/dof %.3f\n", map_scale,
                e.scale, 1.0 / map_scale, e.relative_sigma, e.landmarks, e.reduced_chi2);
    ASSERT_TRUE(e.ok);
    EXPECT_LT(e.relative_sigma, 0.05);
    EXPECT_NEAR(e.scale * map_scale, 1.0, 3.0 * e.relative_sigma);
    // At the minimum the residuals are the noise: 0.5 px against the octave's 1 px sigma, chi2/dof 0.25.
    EXPECT_NEAR(e.reduced_chi2, 0.25, 0.04);
  }
}

// A unit taken as known is refined from where it is; when that refinement finds no minimum near it (the map's
// unit is in fact far off), the coarse search runs after all: the estimate is the window's, not a refinement
// stopped far from its minimum, or one that never moved, passed off as precise.
TEST(ScaleEstimator, AKnownUnitFarFromTheWindowsGetsTheCoarseSearch) {
  const Rig rig = test::nonOverlappingRig3();
  for (double map_scale : {0.2, 3.0, 5.0}) {
    Map map(rig, 2000, 14, 4000);
    buildWindow(rig, map, 60.0, map_scale, 0.5);
    ScaleEstimator est(rig, 4000, 8 * 3 * 2000, 14, 1.2f, 8);
    ScaleEstimate e;
    ASSERT_TRUE(est.prepare(map, e));
    est.solve(30.0, true, e);
    std::printf("map scale %.2f, unit taken as known: estimate %.4f (expected %.4f), sigma %.4f\n", map_scale, e.scale,
                1.0 / map_scale, e.relative_sigma);
    ASSERT_TRUE(e.ok);
    EXPECT_NEAR(e.scale * map_scale, 1.0, 3.0 * e.relative_sigma);
  }
}

// Without rotation the lever arms move with the body and the scale stays unknown: a sigma far above 100%
// (about 5000% here) or no estimate, never a confident wrong answer. The damping that steadies the Gauss-Newton
// step once posed as information here (21%).
TEST(ScaleEstimator, StraightWindowLeavesTheScaleOpen) {
  const Rig rig = test::nonOverlappingRig3();
  Map map(rig, 2000, 14, 4000);
  buildWindow(rig, map, 0.0, 2.5, 0.5);
  ScaleEstimator est(rig, 4000, 8 * 3 * 2000, 14, 1.2f, 8);
  const ScaleEstimate e = est.estimate(map, 30.0);
  std::printf("straight: ok %d estimate %.4f sigma %.4f\n", e.ok, e.scale, e.relative_sigma);
  EXPECT_TRUE(!e.ok || e.relative_sigma > 1.0);
}

// Its scratch is sized at construction (the map's keyframe capacity included): no estimate allocates, the first
// one and one over a smaller window included. (The first estimate once sized the keyframe table: a rig whose
// first turn came after the warm-up allocated then, and again after every re-initialization.)
TEST(ScaleEstimator, EstimatesAllocateNothing) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  const Rig rig = test::nonOverlappingRig3();
  Map map(rig, 2000, 14, 4000);
  buildWindow(rig, map, 60.0, 2.5, 0.5);
  ScaleEstimator est(rig, 4000, 8 * 3 * 2000, 14, 1.2f, 8);
  alloc::ThreadScope scope;
  const ScaleEstimate full = est.estimate(map, 30.0);
  for (int left = 0; left < 3; ++left) map.eraseKeyframe(map.newestKeyframe());  // three keyframes leave
  const ScaleEstimate smaller = est.estimate(map, 1.0);
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_TRUE(full.ok);
  EXPECT_EQ(full.keyframes, 8);
  EXPECT_EQ(smaller.keyframes, 5);
}

// A live rig (mcslamd) takes the estimate at the first settled keyframe that finds it done, never waiting for it:
// the keyframes before that take nothing, and the one that takes it gets the rescale a repeatable run gets.
TEST(ScaleSupervisor, ALiveRigTakesTheEstimateOnceDoneWithTheSameRescale) {
  ScaleSupervisor::Rescale taken[2];
  for (const bool repeatable : {true, false}) {
    OdometryOptions options;
    options.repeatable = repeatable;
    SupervisedWindow w(options);
    OdometryStats& stats = w.stats;
    w.supervisor.startEstimate(w.map, w.state, 1.0, 10);
    ScaleSupervisor::Rescale& r = taken[repeatable ? 0 : 1];
    // Keyframes come until one finds it done (a repeatable run waits at the first); CTest's timeout bounds the loop.
    int keyframes = 0;
    for (; stats.scale_estimates == 0; ++keyframes) {
      r = w.supervisor.takeEstimate(w.map, w.state, 13 + keyframes, stats);
      if (stats.scale_estimates == 0) {
        EXPECT_FALSE(r.apply);
        std::this_thread::sleep_for(std::chrono::microseconds(100));
      }
    }
    EXPECT_EQ(stats.scale_estimates, 1u);
    if (repeatable) {
      EXPECT_EQ(keyframes, 1);
    }
    ASSERT_TRUE(r.apply) << "repeatable " << repeatable;
  }
  EXPECT_EQ(taken[0].s, taken[1].s);
  EXPECT_EQ(taken[0].center, taken[1].center);
}

// An estimate is copied out of the map at one settled keyframe and taken at the next, with the same result whether
// it ran on the supervisor's thread or at once, and whatever the map did in between (tracking goes on).
TEST(ScaleSupervisor, AnEstimateStartedAtOneKeyframeIsTakenAtTheNextWhereverItRan) {
  ScaleSupervisor::Rescale taken[2];
  for (const bool thread : {false, true}) {
    OdometryOptions options;
    options.backend_thread = thread;
    SupervisedWindow w(options);
    OdometryStats& stats = w.stats;
    EXPECT_FALSE(w.supervisor.takeEstimate(w.map, w.state, 10, stats).apply);  // none was started
    w.supervisor.startEstimate(w.map, w.state, 1.0, 10);
    const int newest = w.map.newestKeyframe();
    w.map.keyframe(newest).T_w_b.t += Vec3(3.0, 0, 0);  // the copy is what counts
    ScaleSupervisor::Rescale& r = taken[thread ? 1 : 0];
    r = w.supervisor.takeEstimate(w.map, w.state, 13, stats);
    EXPECT_EQ(stats.scale_estimates, 1u);
    ASSERT_TRUE(r.apply) << "thread " << thread;
    EXPECT_NEAR(r.s * 2.5, 1.0, 0.05);
    EXPECT_FALSE(w.supervisor.takeEstimate(w.map, w.state, 16, stats).apply);  // taken once
    EXPECT_EQ(stats.scale_estimates, 1u);
  }
  EXPECT_EQ(taken[0].s, taken[1].s);
  EXPECT_EQ(taken[0].center, taken[1].center);
}

// A new map drops the estimate in flight: its window belonged to the old one.
TEST(ScaleSupervisor, ANewMapDropsTheEstimateInFlight) {
  SupervisedWindow w(OdometryOptions{});
  w.supervisor.startEstimate(w.map, w.state, 1.0, 10);
  w.supervisor.start(true);
  EXPECT_FALSE(w.supervisor.takeEstimate(w.map, w.state, 13, w.stats).apply);
  EXPECT_EQ(w.stats.scale_estimates, 0u);
}

// The filter says over how much rotation its estimates were gathered, from the first one it kept since it
// (re)started: the odometry declares a scale metric only when that spans two corners' worth.
TEST(ScaleFilter, RotationSpanCountsFromTheFirstEstimateKept) {
  ScaleFilter f;
  EXPECT_EQ(f.rotationSpan(), 0.0);
  EXPECT_TRUE(f.add(0.0, 0.02, 0, 13, 1.0));
  EXPECT_TRUE(f.add(0.01, 0.02, 4, 17, 2.5));
  EXPECT_DOUBLE_EQ(f.rotationSpan(), 1.5);
  // Three windows in a row far off: the map's scale moved, the combination restarts from the third.
  EXPECT_FALSE(f.add(1.0, 0.02, 5, 18, 3.0));
  EXPECT_FALSE(f.add(1.0, 0.02, 6, 19, 3.2));
  EXPECT_TRUE(f.add(1.0, 0.02, 7, 20, 3.4));
  EXPECT_DOUBLE_EQ(f.rotationSpan(), 0.0);
  EXPECT_TRUE(f.add(1.0, 0.02, 8, 21, 4.0));
  EXPECT_NEAR(f.rotationSpan(), 0.6, 1e-12);
  f.reset();
  EXPECT_EQ(f.rotationSpan(), 0.0);
}

// Of windows that share keyframes only the most certain counts (the later ones of a turn hold the earlier
// ones' keyframes and more of the turn); windows that share none are independent and their information adds.
TEST(ScaleFilter, OverlappingWindowsCountOnceDisjointOnesAdd) {
  ScaleFilter f;
  EXPECT_TRUE(f.add(0.10, 0.20, 0, 13, 0.0));  // before the turn: little information
  EXPECT_TRUE(f.add(0.20, 0.03, 3, 16, 0.5));  // in it: this one supersedes the first
  EXPECT_NEAR(f.correction(), 0.20, 1e-12);
  EXPECT_NEAR(f.sigma(), 0.03, 1e-12);
  EXPECT_TRUE(f.add(0.19, 0.05, 6, 19, 0.9));  // less certain, overlapping: adds nothing
  EXPECT_NEAR(f.sigma(), 0.03, 1e-12);
  EXPECT_TRUE(f.add(0.22, 0.03, 17, 30, 3.0));  // shares no keyframe with the pending one: both count
  EXPECT_NEAR(f.correction(), 0.21, 1e-12);
  EXPECT_NEAR(f.sigma(), 0.03 / std::sqrt(2.0), 1e-12);
  // The map takes the correction: the estimates stay, relative to its new unit.
  f.applied();
  EXPECT_NEAR(f.correction(), 0.0, 1e-12);
  EXPECT_NEAR(f.sigma(), 0.03 / std::sqrt(2.0), 1e-12);
}

// With a drift set (after convergence) what is known of the unit fades over the keyframes between windows: the
// next turn's windows then correct the straight's drift instead of being averaged with the turn before.
TEST(ScaleFilter, WithADriftWhatIsKnownFadesOverKeyframes) {
  for (const bool drift : {false, true}) {
    ScaleFilter f;
    EXPECT_TRUE(f.add(0.0, 0.02, 0, 13, 0.0));
    if (drift) f.setDrift(0.01);
    EXPECT_TRUE(f.add(0.06, 0.02, 50, 63, 1.0));  // 50 keyframes later, sharing none
    if (drift) {
      const double faded = 1.0 / (0.02 * 0.02 + 50 * 0.01 * 0.01), fresh = 1.0 / (0.02 * 0.02);
      EXPECT_NEAR(f.correction(), 0.06 * fresh / (faded + fresh), 1e-12);  // 0.0559
      EXPECT_NEAR(f.sigma(), 1.0 / std::sqrt(faded + fresh), 1e-12);
    } else {
      EXPECT_NEAR(f.correction(), 0.03, 1e-12);
      EXPECT_NEAR(f.sigma(), 0.02 / std::sqrt(2.0), 1e-12);
    }
  }
}

TEST(ScaleFilter, ACertainWindowThatContradictsTheFadedPastOutweighsIt) {
  // Committed 0 +- 1.5%, faded over 20 keyframes at 1% each to +- 4.7%; then a turn says -0.09 +- 3%: 1.6 sigma
  // off, more than both sigmas allow, so the committed variance becomes what the disagreement shows.
  const double var_faded = 0.015 * 0.015 + 20 * 0.01 * 0.01, fresh = 1.0 / (0.03 * 0.03);
  for (const bool drift : {false, true}) {
    ScaleFilter f;
    EXPECT_TRUE(f.add(0.0, 0.015, 0, 13, 0.0));
    if (drift) f.setDrift(0.01);
    EXPECT_TRUE(f.add(-0.09, 0.03, 20, 33, 1.0));
    const double committed = drift ? 1.0 / (0.09 * 0.09 - 0.03 * 0.03) : 1.0 / (0.015 * 0.015);
    EXPECT_NEAR(f.correction(), -0.09 * fresh / (committed + fresh), 1e-12);  // -0.080 (without matching -0.064)
    EXPECT_NEAR(f.sigma(), 1.0 / std::sqrt(committed + fresh), 1e-12);
  }
  // A window less certain than the committed part leaves it as the drift left it, however far off it is.
  ScaleFilter f;
  EXPECT_TRUE(f.add(0.0, 0.015, 0, 13, 0.0));
  f.setDrift(0.01);
  EXPECT_TRUE(f.add(-0.3, 0.1, 20, 33, 1.0));
  const double committed = 1.0 / var_faded, uncertain = 1.0 / (0.1 * 0.1);
  EXPECT_NEAR(f.correction(), -0.3 * uncertain / (committed + uncertain), 1e-12);
}

// Windows that overlap share their data: in a map a fast corner broke they agree with each other, however wrong.
// Once converged, a restart needs rejected windows that include two sharing no keyframe.
TEST(ScaleFilter, OnceConvergedARestartNeedsRejectedWindowsThatShareNoKeyframe) {
  ScaleFilter f;
  EXPECT_TRUE(f.add(0.0, 0.02, 0, 13, 0.0));
  f.setDrift(0.01);
  EXPECT_FALSE(f.add(1.0, 0.02, 14, 27, 1.0));
  EXPECT_FALSE(f.add(1.0, 0.02, 15, 28, 1.1));
  EXPECT_FALSE(f.add(1.0, 0.02, 16, 29, 1.2));  // the third in a row, but all share keyframes 16-27
  EXPECT_NEAR(f.correction(), 0.0, 1e-12);
  EXPECT_TRUE(f.add(1.0, 0.02, 28, 41, 2.0));  // none shared with the first: the scale moved
  EXPECT_NEAR(f.correction(), 1.0, 1e-12);
  EXPECT_NEAR(f.sigma(), 0.02, 1e-12);
}
