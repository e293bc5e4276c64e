// Fixed memory: once the window has slid through warm-up (first solves, first
// marginalization), a whole keyframe step -- marginalize, add keyframe, landmarks and
// observations, solve (CHOLMOD's analysis and factorization included), remove outliers --
// makes no heap allocation. CHOLMOD's memory comes from the solver's arena.
#include <gtest/gtest.h>

#include "alloc_testing.hpp"
#include "backend_testkit.hpp"

using namespace mcslam;
using namespace mcslam::backend;
using namespace mcslam::backend::testkit;

TEST(FixedMemory, NoAllocationPerKeyframeAfterWarmUp) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  SceneOptions so;
  so.num_keyframes = 24;
  so.landmarks_per_keyframe = 60;
  so.outlier_fraction = 0.01;
  so.seed = 61;
  const Scene scene = makeScene(isecRig(), so);
  SolverOptions options;
  options.refine_extrinsics = true;  // the prior and first-estimate Jacobians are exercised too
  SlidingWindowSolver solver(scene.rig, {8, 4096, 65536}, options);
  SlidingRunOptions ro;
  ro.iterations = 5;
  const SlidingRunResult run = runSliding(solver, scene, ro);
  ASSERT_GT(run.marginalizations, 10);
  EXPECT_EQ(run.refused, 0);
  ASSERT_GT(run.outliers_removed, 0);
  const int warm_up = 10;  // the window filled (8) and slid twice
  for (int k = warm_up; k < so.num_keyframes; ++k) EXPECT_EQ(run.allocations[k], 0u) << "keyframe " << k;
  EXPECT_EQ(solver.cholmodArenaOverflows(), 0u);
  RecordProperty("cholmod_arena_peak_bytes", std::to_string(solver.cholmodArenaPeakBytes()));
}

// A window cleared after a run (a tracking loss drops the map) allocates nothing, and then solves the next run
// exactly as a window built anew: nothing of the first run is left in it (prior, extrinsics, gauge settings).
TEST(FixedMemory, AClearedWindowIsAFreshOneWithoutAllocating) {
  SceneOptions so;
  so.num_keyframes = 16;
  so.landmarks_per_keyframe = 60;
  so.seed = 62;
  const Scene scene = makeScene(isecRig(), so);
  SolverOptions options;
  options.refine_extrinsics = true;
  SlidingWindowSolver used(scene.rig, {8, 4096, 65536}, options), fresh(scene.rig, {8, 4096, 65536}, options);
  SlidingRunOptions ro;
  ro.iterations = 5;
  runSliding(used, scene, ro);
  used.setGaugeFixedOldest(2);
  ASSERT_GT(used.numKeyframes(), 0);
  {
    alloc::ThreadScope scope;
    used.clear();
    if (test::countsAllocations()) {
      EXPECT_EQ(scope.count(), 0u);
    }
  }
  EXPECT_EQ(used.numKeyframes(), 0);
  EXPECT_EQ(used.numLandmarks(), 0);
  EXPECT_EQ(used.numObservations(), 0);
  EXPECT_EQ(used.priorInformation().norm(), 0.0);
  ro.seed = 8;
  const SlidingRunResult again = runSliding(used, scene, ro);
  const SlidingRunResult anew = runSliding(fresh, scene, ro);
  ASSERT_EQ(again.T_w_b.size(), anew.T_w_b.size());
  for (std::size_t k = 0; k < anew.T_w_b.size(); ++k) {
    EXPECT_EQ(again.T_w_b[k].t, anew.T_w_b[k].t) << "keyframe " << k;
    EXPECT_EQ(again.T_w_b[k].R, anew.T_w_b[k].R) << "keyframe " << k;
  }
  for (int c = 0; c < scene.rig.size(); ++c) EXPECT_EQ(used.extrinsic(c).t, fresh.extrinsic(c).t) << "camera " << c;
  EXPECT_EQ(used.priorInformation(), fresh.priorInformation());
}

TEST(FixedMemory, CountingWorksHere) {
  // The counter sees a heap allocation in this test binary, so zero above means zero.
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  alloc::ThreadScope scope;
  std::vector<double> v(100);
  v[0] = 1;
  EXPECT_GE(scope.count(), 1u);
}
