// The per-frame pose path allocates nothing after construction (fixed-memory rule). malloc and
// operator new are counted per thread by mcslam_alloc_hooks.
#include <gtest/gtest.h>

#include "alloc_testing.hpp"
#include "mcslam/core/alloc_counter.hpp"
#include "mcslam/geometry/absolute_pose_ransac.hpp"
#include "mcslam/geometry/generalized_p3p.hpp"
#include "mcslam/geometry/pose_refinement.hpp"
#include "pose_scenes.hpp"

using namespace mcslam;
using namespace mcslam::test;

TEST(PoseSolversAllocation, HooksAreLinked) { SKIP_UNLESS_COUNTING_ALLOCATIONS(); }

TEST(PoseSolversAllocation, GeneralizedP3PAllocatesNothing) {
  const Rig rig = ringRig();
  SceneRandom r(41);
  const PoseScene scene = makePoseScene(rig, 300, 0.0, 0.0, 1.0, r);
  GeneralizedP3PSolutions solutions;
  int total = 0;
  alloc::ThreadScope scope;
  for (size_t i = 0; i + 2 < scene.observations.size(); i += 3) {
    const auto& o = scene.observations;
    total += solveGeneralizedP3P({o[i].ray, o[i + 1].ray, o[i + 2].ray},
                                 {o[i].point_w, o[i + 1].point_w, o[i + 2].point_w}, solutions);
  }
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_GE(total, 100);  // the calls did real work
}

TEST(PoseSolversAllocation, RansacAndRefinementAllocateNothingAfterWarmUp) {
  for (const NamedRig& shape : allRigShapes()) {
    SceneRandom r(43);
    std::vector<PoseScene> frames;
    for (int f = 0; f < 4; ++f) frames.push_back(makePoseScene(shape.rig, 400, 0.4, 1.0, 1.0, r));
    AbsolutePoseRansac ransac(shape.rig, 500);
    PoseRefiner refiner(shape.rig, 500);
    // Warm-up: first call of each (nothing is expected to allocate, but lazy statics may).
    const AbsolutePoseRansacResult warm = ransac.estimate(frames[0].observations);
    refiner.refine(frames[0].observations, warm.T_w_b, warm.inlier_mask);

    int inliers = 0;
    alloc::ThreadScope scope;
    for (const PoseScene& frame : frames) {
      const SE3 prediction = frame.T_w_b * SE3::exp(Vec6::Constant(0.01));
      const AbsolutePoseRansacResult res = ransac.estimate(frame.observations, &prediction);
      const PoseRefinementResult refined = refiner.refine(frame.observations, res.T_w_b, res.inlier_mask);
      inliers += refined.num_inliers;
    }
    EXPECT_EQ(scope.count(), 0u) << shape.name;
    EXPECT_GT(inliers, 4 * 200) << shape.name;
  }
}
