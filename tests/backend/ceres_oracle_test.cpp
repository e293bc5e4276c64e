// Same minimum as Ceres (SPARSE_SCHUR over SuiteSparse, same residuals, same right
// perturbation, same loss, same gauge and extrinsic prior) on identical windows.
#include <gtest/gtest.h>

#include "ceres_window.hpp"

using namespace mcslam;
using namespace mcslam::backend;
using namespace mcslam::backend::testkit;

namespace {

void expectSameMinimum(LossKind loss, unsigned seed) {
  SceneOptions so;
  so.landmarks_per_keyframe = 40;
  so.outlier_fraction = 0.03;  // so the robust loss is active
  so.seed = seed;
  const Scene scene = makeScene(isecRig(), so);
  const WindowGuess guess = perturbedGuess(scene, 0.03, 0.01, 0.15, seed + 1);
  const Rig solver_rig = perturbExtrinsic(scene.rig, 2, 0.01, 0.5 * M_PI / 180);

  SolverOptions options;
  options.loss.kind = loss;
  options.refine_extrinsics = true;
  // Both stop at a relative cost change of 1e-10, four orders below what is compared.
  options.function_tolerance = 1e-10;
  options.gradient_tolerance = 1e-12;
  options.parameter_tolerance = 1e-15;
  SlidingWindowSolver solver(solver_rig, {10, 2048, 32768}, options);
  fillSolver(solver, scene, guess);
  const SolveSummary ours = solver.solve(200);

  auto window = buildCeresWindow(scene, guess, solver_rig, options);
  ceres::Solver::Options co = ceresOptions(200, 1e-15);
  co.function_tolerance = options.function_tolerance;
  setSchurOrdering(co, *window);
  ceres::Solver::Summary theirs;
  ceres::Solve(co, window->problem.get(), &theirs);
  ASSERT_TRUE(theirs.IsSolutionUsable()) << theirs.FullReport();

  // Both start from the same cost: the cost functions agree.
  EXPECT_NEAR(ours.initial_cost, theirs.initial_cost, 1e-9 * theirs.initial_cost);
  EXPECT_LT(std::abs(ours.final_cost - theirs.final_cost), 1e-6 * theirs.final_cost)
      << "ours " << ours.final_cost << " ceres " << theirs.final_cost;
  EXPECT_LT(ours.final_cost, 0.1 * ours.initial_cost);
  for (size_t k = 0; k < scene.T_w_b.size(); ++k) {
    SE3 T;
    solver.keyframePose(k, T);
    EXPECT_LT((T.t - window->pose(k).t).norm(), 1e-5) << k;
    EXPECT_LT(rotationAngle(T.R, window->pose(k).R), 1e-6) << k;
  }
  for (int c = 0; c < scene.rig.size(); ++c) EXPECT_LT((solver.extrinsic(c).t - window->extrinsic(c).t).norm(), 1e-5);
}

}  // namespace

TEST(CeresOracle, SameMinimumWithHuber) { expectSameMinimum(LossKind::Huber, 51); }
TEST(CeresOracle, SameMinimumWithCauchy) { expectSameMinimum(LossKind::Cauchy, 52); }
