// The pose graph: a consistent graph stays as it is; a drifting loop closed by one edge is pulled back onto the
// truth; the optimum is a stationary point of the true cost (no small move of any free pose lowers it); fixed
// nodes do not move; optimizing allocates nothing, also after the graph grew.
#include <gtest/gtest.h>

#include <random>

#include "alloc_testing.hpp"
#include "mcslam/backend/pose_graph.hpp"

namespace mcslam::backend {
namespace {

Vec6 sigmas(double translation, double rotation) {
  Vec6 s;
  s << translation, translation, translation, rotation, rotation, rotation;
  return s;
}

// Poses on a circle of radius 10 m in the xy plane, heading along it, with a little height and tilt wobble.
std::vector<SE3> circle(int n) {
  std::vector<SE3> poses;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    const Mat3 R = so3Exp(Vec3(0.02 * std::sin(3 * a), 0.01, a + M_PI / 2));
    poses.push_back({R, Vec3(10 * std::cos(a), 10 * std::sin(a), 0.2 * std::sin(2 * a))});
  }
  return poses;
}

// Odometry of the poses with a yaw drift per step and noise: what a visual odometry would measure.
struct Odometry {
  std::vector<SE3> relative;  // T_i_i+1 measured
  std::vector<SE3> chained;   // poses by chaining them from the first
};

Odometry drifting(const std::vector<SE3>& truth, double yaw_drift, double noise, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0, noise);
  Odometry o;
  o.chained.push_back(truth[0]);
  for (std::size_t i = 0; i + 1 < truth.size(); ++i) {
    SE3 rel = truth[i].inverse() * truth[i + 1];
    Vec6 err;
    err << n(rng), n(rng), n(rng), n(rng) * 0.1, n(rng) * 0.1, yaw_drift + n(rng) * 0.1;
    rel = rel * SE3::exp(err);
    o.relative.push_back(rel);
    o.chained.push_back(o.chained.back() * rel);
  }
  return o;
}

double positionRmse(const PoseGraph& g, const std::vector<SE3>& truth) {
  double s = 0;
  for (int i = 0; i < g.nodes(); ++i) s += (g.pose(i).t - truth[static_cast<std::size_t>(i)].t).squaredNorm();
  return std::sqrt(s / g.nodes());
}

double totalCost(const PoseGraph& g) {
  double c = 0;
  for (int e = 0; e < g.edges(); ++e) c += 0.5 * g.residual(e).squaredNorm();
  return c;
}

TEST(PoseGraph, AConsistentGraphStays) {
  const auto truth = circle(40);
  PoseGraph g(64, 128);
  for (int i = 0; i < 40; ++i) g.addNode(truth[static_cast<std::size_t>(i)], i == 0);
  for (int i = 0; i + 1 < 40; ++i)
    g.addEdge(i, i + 1, truth[static_cast<std::size_t>(i)].inverse() * truth[static_cast<std::size_t>(i + 1)],
              sigmas(0.01, 0.001));
  const PoseGraphSummary s = g.optimize();
  EXPECT_TRUE(s.solved);
  EXPECT_LT(s.final_cost, 1e-12);
  EXPECT_LT(positionRmse(g, truth), 1e-9);
}

TEST(PoseGraph, ALoopEdgeTakesTheDriftOut) {
  const int n = 200;
  const auto truth = circle(n);
  const Odometry odo = drifting(truth, 0.002, 0.002, 3);  // 0.4 rad of yaw drift over the loop
  PoseGraph g(256, 512);
  for (int i = 0; i < n; ++i) g.addNode(odo.chained[static_cast<std::size_t>(i)], i == 0);
  for (int i = 0; i + 1 < n; ++i) g.addEdge(i, i + 1, odo.relative[static_cast<std::size_t>(i)], sigmas(0.02, 0.002));
  const double before = positionRmse(g, truth);
  // The last pose recognizes the first place: the true relative pose, more certain than the odometry.
  g.addEdge(n - 1, 0, truth[n - 1].inverse() * truth[0], sigmas(0.01, 0.001));
  const PoseGraphSummary s = g.optimize();
  ASSERT_TRUE(s.solved);
  const double after = positionRmse(g, truth);
  EXPECT_GT(before, 2.0);
  EXPECT_LT(after, 0.1 * before);
  EXPECT_LT((g.pose(n - 1).t - truth[n - 1].t).norm(), 0.2);
  EXPECT_EQ(g.pose(0).t, odo.chained[0].t);  // the fixed node
  EXPECT_LT(s.final_cost, 0.01 * s.initial_cost);
}

TEST(PoseGraph, TheOptimumIsAStationaryPointOfTheCost) {
  const int n = 60;
  const auto truth = circle(n);
  const Odometry odo = drifting(truth, 0.01, 0.01, 5);
  PoseGraph g(64, 256);
  for (int i = 0; i < n; ++i) g.addNode(odo.chained[static_cast<std::size_t>(i)], i == 0);
  for (int i = 0; i + 1 < n; ++i) g.addEdge(i, i + 1, odo.relative[static_cast<std::size_t>(i)], sigmas(0.05, 0.01));
  for (int i = 0; i + 10 < n; i += 7)  // loop edges everywhere, with noise: no graph without tension
    g.addEdge(i + 10, i,
              truth[static_cast<std::size_t>(i + 10)].inverse() * truth[static_cast<std::size_t>(i)] *
                  SE3::exp(Vec6::Constant(0.01)),
              sigmas(0.03, 0.005));
  PoseGraphOptions options;
  options.max_iterations = 100;
  options.function_tolerance = 1e-16;
  g.optimize(options);
  const double optimum = totalCost(g);
  const double h = 1e-5;
  for (int node = 1; node < n; node += 5) {
    for (int k = 0; k < 6; ++k) {
      const SE3 T = g.pose(node);
      Vec6 d = Vec6::Zero();
      d[k] = h;
      g.setPose(node, T * SE3::exp(d));
      const double plus = totalCost(g);
      g.setPose(node, T * SE3::exp(-d));
      const double minus = totalCost(g);
      g.setPose(node, T);
      const double gradient = (plus - minus) / (2 * h);
      EXPECT_LT(std::abs(gradient), 1e-3 * (1 + optimum)) << "node " << node << " direction " << k;
    }
  }
}

TEST(PoseGraph, OptimizingAllocatesNothingAlsoAfterTheGraphGrew) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  const int n = 300;
  const auto truth = circle(n);
  const Odometry odo = drifting(truth, 0.002, 0.002, 7);
  PoseGraph g(n, 2 * n);
  for (int i = 0; i < n / 2; ++i) g.addNode(odo.chained[static_cast<std::size_t>(i)], i == 0);
  for (int i = 0; i + 1 < n / 2; ++i)
    g.addEdge(i, i + 1, odo.relative[static_cast<std::size_t>(i)], sigmas(0.02, 0.002));
  alloc::ThreadScope scope;
  g.optimize();
  for (int i = n / 2; i < n; ++i) {
    g.addNode(odo.chained[static_cast<std::size_t>(i)], false);
    g.addEdge(i - 1, i, odo.relative[static_cast<std::size_t>(i - 1)], sigmas(0.02, 0.002));
  }
  g.addEdge(n - 1, 0, truth[n - 1].inverse() * truth[0], sigmas(0.01, 0.001));
  const PoseGraphSummary s = g.optimize();
  EXPECT_TRUE(s.solved);
  EXPECT_EQ(s.analyses, 2);
  EXPECT_EQ(scope.count(), 0u);
}

}  // namespace
}  // namespace mcslam::backend
