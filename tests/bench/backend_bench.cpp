// Back-end: one sliding-window solve, ours against Ceres on the identical window.
//
// The window: 10 keyframes of the 5-camera ISEC rig, about 2000 landmarks with 3-8 keyframe
// tracks, 0.5 px noise at sigma 1 (octaves 0-3), 1% gross outliers; initial guess 3 cm / 0.6 deg
// per axis on poses, 10 cm on points; extrinsics refined (camera 2 calibrated 1 cm / 0.5 deg
// off) under the calibration prior; Huber loss; first keyframe and camera 0 fixed.
// Both run exactly kIterations Levenberg-Marquardt iterations (tolerances 0), single-threaded,
// SPARSE_SCHUR on SuiteSparse for Ceres. Setup (building the problem) is not timed; the solve
// includes the symbolic analysis for both (a new keyframe changes the structure every time).
#include <benchmark/benchmark.h>

#include "../backend/ceres_window.hpp"

namespace {

using namespace mcslam;
using namespace mcslam::backend;
using namespace mcslam::backend::testkit;

constexpr int kIterations = 10;

struct BenchWindow {
  Scene scene;
  WindowGuess guess;
  Rig solver_rig;
  SolverOptions options;
  int landmarks = 0;
  int observations = 0;
};

const BenchWindow& benchWindow() {
  static const BenchWindow w = [] {
    BenchWindow b;
    SceneOptions so;
    so.num_keyframes = 10;
    so.landmarks_per_keyframe = 215;
    so.outlier_fraction = 0.01;
    so.seed = 101;
    b.scene = makeScene(isecRig(), so);
    b.guess = perturbedGuess(b.scene, 0.03, 0.01, 0.1, 102);
    b.solver_rig = perturbExtrinsic(b.scene.rig, 2, 0.01, 0.5 * M_PI / 180);
    b.options.refine_extrinsics = true;
    b.options.function_tolerance = 0;
    b.options.gradient_tolerance = 0;
    b.options.parameter_tolerance = 0;
    for (size_t l = 0; l < b.scene.points.size(); ++l) b.landmarks += b.scene.num_observations[l] >= 2;
    for (const SceneObservation& ob : b.scene.observations)
      b.observations += b.scene.num_observations[ob.landmark] >= 2;
    return b;
  }();
  return w;
}

void SlidingWindowSolveMcslam(benchmark::State& state) {
  const BenchWindow& w = benchWindow();
  SolveSummary summary;
  for (auto _ : state) {
    state.PauseTiming();
    auto solver = std::make_unique<SlidingWindowSolver>(w.solver_rig, WindowCapacity{10, 4096, 65536}, w.options);
    fillSolver(*solver, w.scene, w.guess);
    state.ResumeTiming();
    summary = solver->solve(kIterations);
    state.PauseTiming();
    solver.reset();
    state.ResumeTiming();
  }
  state.counters["landmarks"] = w.landmarks;
  state.counters["observations"] = w.observations;
  state.counters["iterations"] = summary.iterations;
  state.counters["initial_cost"] = summary.initial_cost;
  state.counters["final_cost"] = summary.final_cost;
}

void SlidingWindowSolveCeres(benchmark::State& state) {
  const BenchWindow& w = benchWindow();
  ceres::Solver::Summary summary;
  for (auto _ : state) {
    state.PauseTiming();
    auto window = buildCeresWindow(w.scene, w.guess, w.solver_rig, w.options);
    ceres::Solver::Options options = ceresOptions(kIterations, 0.0);
    setSchurOrdering(options, *window);
    state.ResumeTiming();
    ceres::Solve(options, window->problem.get(), &summary);
    state.PauseTiming();
    window.reset();
    state.ResumeTiming();
  }
  state.counters["landmarks"] = w.landmarks;
  state.counters["observations"] = w.observations;
  state.counters["iterations"] = static_cast<double>(summary.iterations.size()) - 1;  // [0] is the start
  state.counters["initial_cost"] = summary.initial_cost;
  state.counters["final_cost"] = summary.final_cost;
}

}  // namespace

BENCHMARK(SlidingWindowSolveMcslam)->Name("SlidingWindowSolve/mcslam")->Unit(benchmark::kMillisecond);
BENCHMARK(SlidingWindowSolveCeres)->Name("SlidingWindowSolve/ceres")->Unit(benchmark::kMillisecond);
