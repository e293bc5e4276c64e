// Pose solvers against OpenGV on identical input (docs/benchmarks/geometry.md):
//  - GeneralizedP3P: one minimal problem per iteration, 1024 noise-free problems from the 6-camera
//    ring (rays of random cameras), ours vs opengv::absolute_pose::gp3p (Kneip).
//  - AbsolutePoseRansac: 500 correspondences over the ring's cameras, 50% gross outliers, 1 px
//    noise; ours (gP3P hypotheses, MSAC, refinement of the winner) vs OpenGV's Ransac with its
//    AbsolutePoseSacProblem(GP3P); same iteration cap, same confidence, same inlier threshold
//    (chi-square 5.991 at 1 px, converted to OpenGV's 1 - cos(angle) at the focal length).
//  - PoseRefinement: the refinement over those 500 (ours: robust, 4 rounds) vs
//    opengv::absolute_pose::optimize_nonlinear on the true inliers (least squares, no outlier rounds).
// Inputs are seeded; counters report accuracy next to the time (their bookkeeping, a few dozen ns,
// is inside the timed loop for both sides alike).
#include <benchmark/benchmark.h>

#include <opengv/absolute_pose/NoncentralAbsoluteAdapter.hpp>
#include <opengv/absolute_pose/methods.hpp>
#include <opengv/sac/Ransac.hpp>
#include <opengv/sac_problems/absolute_pose/AbsolutePoseSacProblem.hpp>

#include <memory>
#include <vector>

#include "../geometry/pose_scenes.hpp"
#include "mcslam/geometry/absolute_pose_ransac.hpp"
#include "mcslam/geometry/generalized_p3p.hpp"
#include "mcslam/geometry/pose_refinement.hpp"

namespace {

using namespace mcslam;
using namespace mcslam::test;

constexpr int kProblems = 1024;
constexpr int kFrames = 8;
constexpr int kCorrespondences = 500;
constexpr int kMaxIterations = 500;
constexpr double kConfidence = 0.99;  // OpenGV's default

const Rig& benchRig() {
  static const Rig rig = ringRig();
  return rig;
}

// OpenGV's view of a set of correspondences: camera-frame bearings, camera indices, points, rig.
struct OpenGvData {
  opengv::bearingVectors_t bearings;
  std::vector<int> cameras;
  opengv::points_t points;
  opengv::translations_t offsets;
  opengv::rotations_t rotations;
  explicit OpenGvData(const std::vector<PoseObservation>& obs) {
    const Rig& rig = benchRig();
    for (const PoseObservation& o : obs) {
      bearings.push_back(rig.T_b_c(o.camera).R.transpose() * o.ray.direction);
      cameras.push_back(o.camera);
      points.push_back(o.point_w);
    }
    for (const RigCamera& c : rig.cameras) {
      offsets.push_back(c.T_b_c.t);
      rotations.push_back(c.T_b_c.R);
    }
  }
};

// kProblems minimal problems as 3 consecutive noise-free correspondences each.
const PoseScene& p3pProblems() {
  static const PoseScene scene = [] {
    SceneRandom r(101);
    PoseScene all;
    for (int p = 0; p < kProblems; ++p) {
      const PoseScene s = makePoseScene(benchRig(), 3, 0.0, 0.0, 1.0, r);
      all.observations.insert(all.observations.end(), s.observations.begin(), s.observations.end());
    }
    return all;
  }();
  return scene;
}

const std::vector<PoseScene>& ransacFrames() {
  static const std::vector<PoseScene> frames = [] {
    SceneRandom r(202);
    std::vector<PoseScene> v;
    for (int f = 0; f < kFrames; ++f) v.push_back(makePoseScene(benchRig(), kCorrespondences, 0.5, 1.0, 1.0, r));
    return v;
  }();
  return frames;
}

void GeneralizedP3PMcslam(benchmark::State& state) {
  const auto& obs = p3pProblems().observations;
  GeneralizedP3PSolutions solutions;
  int p = 0;
  int64_t total = 0;
  for (auto _ : state) {
    const PoseObservation* o = &obs[3 * p];
    total += solveGeneralizedP3P({o[0].ray, o[1].ray, o[2].ray}, {o[0].point_w, o[1].point_w, o[2].point_w}, solutions);
    benchmark::DoNotOptimize(solutions);
    p = (p + 1) % kProblems;
  }
  state.counters["solutions_per_call"] = benchmark::Counter(double(total) / state.iterations());
}

void GeneralizedP3POpenGv(benchmark::State& state) {
  const OpenGvData data(p3pProblems().observations);
  const opengv::absolute_pose::NoncentralAbsoluteAdapter adapter(data.bearings, data.cameras, data.points, data.offsets,
                                                                 data.rotations);
  int p = 0;
  int64_t total = 0;
  for (auto _ : state) {
    const opengv::transformations_t solutions = opengv::absolute_pose::gp3p(adapter, 3 * p, 3 * p + 1, 3 * p + 2);
    total += static_cast<int64_t>(solutions.size());
    benchmark::DoNotOptimize(solutions.data());
    p = (p + 1) % kProblems;
  }
  state.counters["solutions_per_call"] = benchmark::Counter(double(total) / state.iterations());
}

void AbsolutePoseRansacMcslam(benchmark::State& state) {
  AbsolutePoseRansacOptions options;
  options.max_iterations = kMaxIterations;
  options.confidence = kConfidence;
  AbsolutePoseRansac ransac(benchRig(), kCorrespondences, options);
  int f = 0;
  double iterations = 0, rotation_error = 0, inliers = 0;
  for (auto _ : state) {
    const PoseScene& frame = ransacFrames()[f];
    const AbsolutePoseRansacResult res = ransac.estimate(frame.observations);
    benchmark::DoNotOptimize(res.T_w_b);
    iterations += res.iterations;
    inliers += res.num_inliers;
    rotation_error += rotationErrorDeg(res.T_w_b, frame.T_w_b);
    f = (f + 1) % kFrames;
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["samples"] = iterations / n;
  state.counters["inliers"] = inliers / n;
  state.counters["rot_err_deg"] = rotation_error / n;
}

void AbsolutePoseRansacOpenGv(benchmark::State& state) {
  std::vector<OpenGvData> data;
  for (const PoseScene& frame : ransacFrames()) data.emplace_back(frame.observations);
  // Our inlier test (chi-square 5.991 at sigma 1 px) as OpenGV's bearing threshold 1 - cos(angle).
  const double focal = pinholeRadtan().fx();
  const double threshold = 1.0 - std::cos(std::atan(std::sqrt(5.991) * 1.0 / focal));
  using Problem = opengv::sac_problems::absolute_pose::AbsolutePoseSacProblem;
  int f = 0;
  double iterations = 0, rotation_error = 0, inliers = 0;
  for (auto _ : state) {
    const OpenGvData& d = data[f];
    opengv::absolute_pose::NoncentralAbsoluteAdapter adapter(d.bearings, d.cameras, d.points, d.offsets, d.rotations);
    opengv::sac::Ransac<Problem> ransac;
    ransac.sac_model_ = std::make_shared<Problem>(adapter, Problem::GP3P, false);
    ransac.threshold_ = threshold;
    ransac.max_iterations_ = kMaxIterations;
    ransac.probability_ = kConfidence;
    ransac.computeModel();
    benchmark::DoNotOptimize(ransac.model_coefficients_);
    const auto& M = ransac.model_coefficients_;
    iterations += ransac.iterations_;
    inliers += static_cast<double>(ransac.inliers_.size());
    rotation_error += rotationErrorDeg(SE3(M.leftCols<3>(), M.col(3)), ransacFrames()[f].T_w_b);
    f = (f + 1) % kFrames;
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["samples"] = iterations / n;
  state.counters["inliers"] = inliers / n;
  state.counters["rot_err_deg"] = rotation_error / n;
}

// Start 1 degree and 5 cm off the truth, as a motion-model prediction might be.
SE3 perturbedStart(const SE3& truth) {
  return truth * SE3::exp((Vec6() << 0.03, -0.04, 0.0, 0.01, -0.012, 0.008).finished());
}

void PoseRefinementMcslam(benchmark::State& state) {
  PoseRefiner refiner(benchRig(), kCorrespondences);
  int f = 0;
  double rotation_error = 0, trials = 0;
  for (auto _ : state) {
    const PoseScene& frame = ransacFrames()[f];
    const PoseRefinementResult res = refiner.refine(frame.observations, perturbedStart(frame.T_w_b));
    benchmark::DoNotOptimize(res.T_w_b);
    rotation_error += rotationErrorDeg(res.T_w_b, frame.T_w_b);
    trials += res.iterations;
    f = (f + 1) % kFrames;
  }
  state.counters["rot_err_deg"] = rotation_error / static_cast<double>(state.iterations());
  state.counters["lm_trials"] = trials / static_cast<double>(state.iterations());
}

void PoseRefinementOpenGv(benchmark::State& state) {
  std::vector<OpenGvData> data;
  std::vector<std::vector<int>> inliers;
  for (const PoseScene& frame : ransacFrames()) {
    data.emplace_back(frame.observations);
    inliers.emplace_back();
    for (int i = 0; i < kCorrespondences; ++i)
      if (frame.is_inlier[i]) inliers.back().push_back(i);
  }
  int f = 0;
  double rotation_error = 0;
  for (auto _ : state) {
    const OpenGvData& d = data[f];
    const SE3 start = perturbedStart(ransacFrames()[f].T_w_b);
    opengv::absolute_pose::NoncentralAbsoluteAdapter adapter(d.bearings, d.cameras, d.points, d.offsets, d.rotations,
                                                             start.t, start.R);
    const opengv::transformation_t T = opengv::absolute_pose::optimize_nonlinear(adapter, inliers[f]);
    benchmark::DoNotOptimize(T);
    rotation_error += rotationErrorDeg(SE3(T.leftCols<3>(), T.col(3)), ransacFrames()[f].T_w_b);
    f = (f + 1) % kFrames;
  }
  state.counters["rot_err_deg"] = rotation_error / static_cast<double>(state.iterations());
}

}  // namespace

BENCHMARK(GeneralizedP3PMcslam)->Name("GeneralizedP3P/mcslam")->Unit(benchmark::kMicrosecond);
BENCHMARK(GeneralizedP3POpenGv)->Name("GeneralizedP3P/opengv")->Unit(benchmark::kMicrosecond);
BENCHMARK(AbsolutePoseRansacMcslam)->Name("AbsolutePoseRansac/mcslam")->Unit(benchmark::kMicrosecond);
BENCHMARK(AbsolutePoseRansacOpenGv)->Name("AbsolutePoseRansac/opengv")->Unit(benchmark::kMicrosecond);
BENCHMARK(PoseRefinementMcslam)->Name("PoseRefinement/mcslam")->Unit(benchmark::kMicrosecond);
BENCHMARK(PoseRefinementOpenGv)->Name("PoseRefinement/opengv")->Unit(benchmark::kMicrosecond);
