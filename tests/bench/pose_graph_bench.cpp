// Loop-closure correction: the pose graph of a 1,000-keyframe map (two laps of a 100 m loop with odometry drift,
// one new loop edge from the last keyframe to the first, plus the odometry edges to the second-next keyframe), ours
// against Ceres on the identical graph. Ceres: the pose_graph_3d example's residual (position and quaternion
// vector part of the relative pose error), quaternion manifold, LEVENBERG_MARQUARDT over SPARSE_NORMAL_CHOLESKY
// on SuiteSparse, one thread. Both start from the drifted odometry and stop at a relative cost decrease of 1e-10;
// the symbolic analysis is timed for both (a loop closure changes the structure). Counters: the position RMSE
// against the truth before and after, iterations.
#include <benchmark/benchmark.h>
#include <ceres/ceres.h>

#include <random>

#include "mcslam/backend/pose_graph.hpp"

namespace {

using namespace mcslam;
using namespace mcslam::backend;

constexpr int kKeyframes = 1000;

struct Graph {
  std::vector<SE3> truth, chained;
  struct Edge {
    int a, b;
    SE3 T_a_b;
    Vec6 sigma;
  };
  std::vector<Edge> edges;
};

Vec6 sigmas(double translation, double rotation) {
  Vec6 s;
  s << translation, translation, translation, rotation, rotation, rotation;
  return s;
}

const Graph& benchGraph() {
  static const Graph g = [] {
    Graph out;
    std::mt19937_64 rng(17);
    std::normal_distribution<double> n(0, 1);
    const double radius = 100 / (2 * M_PI);
    for (int i = 0; i < kKeyframes; ++i) {
      const double a = 4 * M_PI * i / kKeyframes;  // two laps
      out.truth.push_back(SE3(so3Exp(Vec3(0.02 * std::sin(5 * a), 0.01 * std::cos(3 * a), a + M_PI / 2)),
                              Vec3(radius * std::cos(a), radius * std::sin(a), 0.1 * std::sin(2 * a))));
    }
    out.chained.push_back(out.truth[0]);
    for (int i = 0; i + 1 < kKeyframes; ++i) {
      for (int step : {1, 2}) {
        if (i + step >= kKeyframes) continue;
        Vec6 err;
        err << 0.005 * n(rng), 0.005 * n(rng), 0.005 * n(rng), 0.0005 * n(rng), 0.0005 * n(rng),
            0.0008 + 0.0005 * n(rng);  // a yaw drift of 0.05 deg per keyframe
        const SE3 rel = out.truth[static_cast<std::size_t>(i)].inverse() *
                        out.truth[static_cast<std::size_t>(i + step)] * SE3::exp(err);
        out.edges.push_back({i, i + step, rel, sigmas(0.01, 0.001)});
        if (step == 1) out.chained.push_back(out.chained.back() * rel);
      }
    }
    out.edges.push_back({kKeyframes - 1, 0, out.truth.back().inverse() * out.truth.front(), sigmas(0.01, 0.001)});
    return out;
  }();
  return g;
}

double rmse(const std::vector<SE3>& poses, const std::vector<SE3>& truth) {
  double s = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) s += (poses[i].t - truth[i].t).squaredNorm();
  return std::sqrt(s / static_cast<double>(poses.size()));
}

void PoseGraphCorrectionMcslam(benchmark::State& state) {
  const Graph& g = benchGraph();
  PoseGraph graph(kKeyframes, 3 * kKeyframes);
  PoseGraphSummary summary;
  std::vector<SE3> result(g.chained.size());
  for (auto _ : state) {
    state.PauseTiming();
    graph.clear();
    for (int i = 0; i < kKeyframes; ++i) graph.addNode(g.chained[static_cast<std::size_t>(i)], i == 0);
    for (const Graph::Edge& e : g.edges) graph.addEdge(e.a, e.b, e.T_a_b, e.sigma);
    state.ResumeTiming();
    PoseGraphOptions options;
    options.max_iterations = 50;
    options.function_tolerance = 1e-10;
    summary = graph.optimize(options);
    state.PauseTiming();
    for (int i = 0; i < kKeyframes; ++i) result[static_cast<std::size_t>(i)] = graph.pose(i);
    graph.clear();  // another structure in between: every timed solve analyses, as after a loop closure
    graph.addNode(SE3(), true);
    graph.addNode(SE3(), false);
    graph.addEdge(0, 1, SE3(), sigmas(1, 1));
    graph.optimize();
    state.ResumeTiming();
  }
  state.counters["rmse_before_m"] = rmse(g.chained, g.truth);
  state.counters["rmse_after_m"] = rmse(result, g.truth);
  state.counters["iterations"] = summary.iterations;
}

// The pose_graph_3d example's residual: [R_a^T (p_b - p_a) - p_ab; 2 vec(q_ab^-1 q_a^-1 q_b)], whitened.
struct RelativePoseError {
  RelativePoseError(const SE3& T_a_b, const Vec6& sigma)
      : p_ab(T_a_b.t), q_ab(T_a_b.quaternion()), w(sigma.cwiseInverse()) {}
  template <class T>
  bool operator()(const T* pa, const T* qa, const T* pb, const T* qb, T* r) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> p_a(pa), p_b(pb);
    const Eigen::Map<const Eigen::Quaternion<T>> q_a(qa), q_b(qb);
    const Eigen::Quaternion<T> q_a_inv = q_a.conjugate();
    const Eigen::Quaternion<T> q_est = q_a_inv * q_b;
    const Eigen::Matrix<T, 3, 1> p_est = q_a_inv * (p_b - p_a);
    const Eigen::Quaternion<T> dq = q_ab.template cast<T>().conjugate() * q_est;
    Eigen::Map<Eigen::Matrix<T, 6, 1>> res(r);
    res.template head<3>() = p_est - p_ab.template cast<T>();
    res.template tail<3>() = T(2.0) * dq.vec();
    for (int k = 0; k < 6; ++k) res[k] *= T(w[k]);
    return true;
  }
  Vec3 p_ab;
  Eigen::Quaterniond q_ab;
  Vec6 w;
};

void PoseGraphCorrectionCeres(benchmark::State& state) {
  const Graph& g = benchGraph();
  std::vector<Vec3> p(g.chained.size());
  std::vector<Eigen::Quaterniond> q(g.chained.size());
  ceres::Solver::Summary summary;
  for (auto _ : state) {
    state.PauseTiming();
    for (std::size_t i = 0; i < p.size(); ++i) {
      p[i] = g.chained[i].t;
      q[i] = g.chained[i].quaternion();
    }
    ceres::Problem problem;
    for (const Graph::Edge& e : g.edges) {
      auto* cost =
          new ceres::AutoDiffCostFunction<RelativePoseError, 6, 3, 4, 3, 4>(new RelativePoseError(e.T_a_b, e.sigma));
      problem.AddResidualBlock(
          cost, nullptr, p[static_cast<std::size_t>(e.a)].data(), q[static_cast<std::size_t>(e.a)].coeffs().data(),
          p[static_cast<std::size_t>(e.b)].data(), q[static_cast<std::size_t>(e.b)].coeffs().data());
    }
    for (auto& qi : q) problem.SetManifold(qi.coeffs().data(), new ceres::EigenQuaternionManifold);
    problem.SetParameterBlockConstant(p[0].data());
    problem.SetParameterBlockConstant(q[0].coeffs().data());
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    options.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
    options.max_num_iterations = 50;
    options.function_tolerance = 1e-10;
    options.num_threads = 1;
    state.ResumeTiming();
    ceres::Solve(options, &problem, &summary);
  }
  std::vector<SE3> result(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) result[i] = SE3(q[i], p[i]);
  state.counters["rmse_before_m"] = rmse(g.chained, g.truth);
  state.counters["rmse_after_m"] = rmse(result, g.truth);
  state.counters["iterations"] = static_cast<double>(summary.iterations.size());
}

}  // namespace

BENCHMARK(PoseGraphCorrectionMcslam)->Name("PoseGraphCorrection1000/mcslam")->Unit(benchmark::kMillisecond);
BENCHMARK(PoseGraphCorrectionCeres)->Name("PoseGraphCorrection1000/ceres")->Unit(benchmark::kMillisecond);
