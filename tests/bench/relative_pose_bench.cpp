// The relative pose of the two-frame initialization against OpenGV on identical input (BENCHMARKS.md, "Relative
// pose"):
//  - FivePoint: one minimal problem per iteration, 256 noise-free problems of one camera; ours (the action matrix
//    of essentialsInSpan) vs opengv::relative_pose::fivept_nister. Counter: share of problems whose true essential
//    matrix is among the solutions.
//  - RelativePose: 300 matches of the non-overlapping rig (0.3 m), 30 deg and 1 m of motion, 20% outliers, 0.3 px
//    noise. Ours: the whole estimation (17-point RANSAC, the 17-point solution on its inliers, the rotation-first
//    hypothesis, refinement, observability) in fixed memory. OpenGV: its RANSAC with the 17-point problem and the
//    17-point solution on its inliers (what our initialization used before it had its own solvers; no
//    refinement). Counters: metric translation error (%) and rotation error (deg).
#include <benchmark/benchmark.h>

#include <opengv/relative_pose/CentralRelativeAdapter.hpp>
#include <opengv/relative_pose/NoncentralRelativeAdapter.hpp>
#include <opengv/relative_pose/methods.hpp>
#include <opengv/sac/Ransac.hpp>
#include <opengv/sac_problems/relative_pose/NoncentralRelativePoseSacProblem.hpp>

#include <memory>
#include <vector>

#include "../geometry/relative_pose_scenes.hpp"
#include "mcslam/geometry/relative_pose.hpp"
#include "mcslam/geometry/relative_pose_solvers.hpp"

namespace {

using namespace mcslam;
using namespace mcslam::test;

constexpr int kFivePointProblems = 256;

struct FivePointProblem {
  std::array<Vec3, 5> d1, d2;
  Mat3 E_true;
};

const std::vector<FivePointProblem>& fivePointProblems() {
  static const std::vector<FivePointProblem> problems = [] {
    const Rig rig = Rig{{{"cam0", pinholeRadtan(), SE3(), 0}}, std::nullopt};
    SceneRandom r(303);
    std::vector<FivePointProblem> v;
    while (static_cast<int>(v.size()) < kFivePointProblems) {
      const TwoFrames f = makeTwoFrames(rig, motion(r.uniform(2, 30), r.pose(1.0).t), 5, 0.0, 0.0, r);
      if (f.matches.size() < 5 || !(f.T_1_2.t.norm() > 0.05)) continue;
      FivePointProblem p;
      for (int i = 0; i < 5; ++i) {
        p.d1[i] = f.matches[i].bearing1.normalized();
        p.d2[i] = f.matches[i].bearing2.normalized();
      }
      p.E_true = (hat(f.T_1_2.t) * f.T_1_2.R).normalized();
      v.push_back(p);
    }
    return v;
  }();
  return problems;
}

// OpenGV's essential matrices may come transposed (its convention of the two views).
bool isTrue(const Mat3& E, const Mat3& E_true) {
  return std::min(essentialDistance(E, E_true), essentialDistance(E.transpose(), E_true)) < 1e-6;
}

void FivePointMcslam(benchmark::State& state) {
  const auto& problems = fivePointProblems();
  std::array<Mat3, 10> E;
  int p = 0;
  int64_t found = 0, calls = 0;
  for (auto _ : state) {
    const int n = relative_pose_detail::fivePointEssential(problems[p].d1, problems[p].d2, E);
    benchmark::DoNotOptimize(E);
    bool hit = false;
    for (int k = 0; k < n; ++k) hit = hit || isTrue(E[k], problems[p].E_true);
    found += hit ? 1 : 0;
    ++calls;
    p = (p + 1) % kFivePointProblems;
  }
  state.counters["true_found"] = benchmark::Counter(double(found) / double(calls));
}

void FivePointOpenGv(benchmark::State& state) {
  const auto& problems = fivePointProblems();
  opengv::bearingVectors_t b1, b2;
  for (const FivePointProblem& p : problems) {
    for (int i = 0; i < 5; ++i) {
      b1.push_back(p.d1[i]);
      b2.push_back(p.d2[i]);
    }
  }
  const opengv::relative_pose::CentralRelativeAdapter adapter(b1, b2);
  int p = 0;
  int64_t found = 0, calls = 0;
  std::vector<int> indices(5);
  for (auto _ : state) {
    for (int i = 0; i < 5; ++i) indices[i] = 5 * p + i;
    const opengv::essentials_t E = opengv::relative_pose::fivept_nister(adapter, indices);
    benchmark::DoNotOptimize(E.data());
    bool hit = false;
    for (const opengv::essential_t& e : E) hit = hit || isTrue(e, problems[p].E_true);
    found += hit ? 1 : 0;
    ++calls;
    p = (p + 1) % kFivePointProblems;
  }
  state.counters["true_found"] = benchmark::Counter(double(found) / double(calls));
}

const Rig& relativeRig() {
  static const Rig rig = wideNonOverlappingRig();
  return rig;
}

const TwoFrames& relativeScene() {
  static const TwoFrames f = [] {
    SceneRandom r(404);
    return makeTwoFrames(relativeRig(), motion(30, Vec3(0.6, 0.05, 0.8)), 300, 0.2, 0.3, r);
  }();
  return f;
}

RelativePoseOptions relativeOptions() {
  RelativePoseOptions o;
  o.bearing_sigma_rad = 1.2 * 0.3 / pinholeRadtan().fx();
  return o;
}

void reportErrors(benchmark::State& state, const SE3& T, const SE3& truth) {
  state.counters["translation_error_pct"] = 100.0 * (T.t - truth.t).norm() / truth.t.norm();
  state.counters["rotation_error_deg"] = rotationErrorDeg(T, truth);
}

void RelativePoseMcslam(benchmark::State& state) {
  const TwoFrames& f = relativeScene();
  RelativePoseEstimator estimator(static_cast<int>(f.matches.size()), relativeRig().size());
  SE3 T;
  for (auto _ : state) {
    const RelativePoseResult& r = estimator.generalized(relativeRig(), f.matches, relativeOptions());
    T = r.T_1_2;
    benchmark::DoNotOptimize(T);
  }
  reportErrors(state, T, f.T_1_2);
}

void RelativePoseOpenGv(benchmark::State& state) {
  const TwoFrames& f = relativeScene();
  const Rig& rig = relativeRig();
  opengv::bearingVectors_t b1, b2;
  std::vector<int> cam1, cam2;
  for (const RelativeCorrespondence& m : f.matches) {
    b1.push_back(m.bearing1.normalized());
    b2.push_back(m.bearing2.normalized());
    cam1.push_back(m.camera1);
    cam2.push_back(m.camera2);
  }
  opengv::translations_t offsets;
  opengv::rotations_t rotations;
  for (const RigCamera& c : rig.cameras) {
    offsets.push_back(c.T_b_c.t);
    rotations.push_back(c.T_b_c.R);
  }
  opengv::relative_pose::NoncentralRelativeAdapter adapter(b1, b2, cam1, cam2, offsets, rotations);
  using Problem = opengv::sac_problems::relative_pose::NoncentralRelativePoseSacProblem;
  const RelativePoseOptions o = relativeOptions();
  SE3 T;
  for (auto _ : state) {
    opengv::sac::Ransac<Problem> ransac;
    ransac.sac_model_ = std::make_shared<Problem>(adapter, Problem::SEVENTEENPT, false, false);
    ransac.threshold_ = 2.0 * (1.0 - std::cos(o.inlier_sigmas * o.bearing_sigma_rad));
    ransac.max_iterations_ = o.max_iterations;
    ransac.probability_ = o.confidence;
    if (ransac.computeModel()) {
      const opengv::transformation_t all = opengv::relative_pose::seventeenpt(adapter, ransac.inliers_);
      T = SE3(all.leftCols<3>(), all.col(3));
    }
    benchmark::DoNotOptimize(T);
  }
  reportErrors(state, T, f.T_1_2);
}

}  // namespace

BENCHMARK(FivePointMcslam)->Name("FivePoint/mcslam")->Unit(benchmark::kMicrosecond);
BENCHMARK(FivePointOpenGv)->Name("FivePoint/opengv")->Unit(benchmark::kMicrosecond);
BENCHMARK(RelativePoseMcslam)->Name("RelativePose/mcslam")->Unit(benchmark::kMillisecond);
BENCHMARK(RelativePoseOpenGv)->Name("RelativePose/opengv")->Unit(benchmark::kMillisecond);
