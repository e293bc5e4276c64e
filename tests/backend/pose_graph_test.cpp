// The pose graph: a consistent graph stays as it is; a drifting loop closed by one edge is pulled back onto the
// truth; the optimum is a stationary point of the true cost (no small move of any free pose lowers it), with
// uncertainties per direction or correlated between directions; fixed
// nodes do not move; optimizing allocates nothing, also after the graph grew. The Sim(3) graph takes out a drift of
// scale, which no SE(3) graph can.
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

// An uncertainty with correlated directions, as the loop closer gives an odometry whose length is less certain than
// its direction: W = (diag(1/sigma) + strictly upper random terms), fixed by the seed.
Mat6 correlatedSqrtInformation(const Vec6& sigma, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  Mat6 W = Mat6::Zero();
  for (int r = 0; r < 6; ++r) {
    W(r, r) = 1 / sigma[r];
    for (int c = r + 1; c < 6; ++c) W(r, c) = u(rng) / std::sqrt(sigma[r] * sigma[c]);
  }
  return W;
}

// The cost as the test states it, from the edges it made: 0.5 |W log(T_ab^-1 T_a^-1 T_b)|^2 summed (not the
// graph's own residual(), which shares the solver's weights and conventions).
struct StatedEdge {
  int a, b;
  SE3 T_a_b;
  Mat6 W;
};

double statedCost(const PoseGraph& g, const std::vector<StatedEdge>& edges) {
  double c = 0;
  for (const StatedEdge& e : edges)
    c += 0.5 * (e.W * (e.T_a_b.inverse() * g.pose(e.a).inverse() * g.pose(e.b)).log()).squaredNorm();
  return c;
}

void expectTheOptimumIsStationary(bool correlated) {
  const int n = 60;
  const auto truth = circle(n);
  const Odometry odo = drifting(truth, 0.01, 0.01, 5);
  PoseGraph g(64, 256);
  for (int i = 0; i < n; ++i) g.addNode(odo.chained[static_cast<std::size_t>(i)], i == 0);
  std::mt19937_64 rng(11);
  std::vector<StatedEdge> edges;
  for (int i = 0; i + 1 < n; ++i) {
    const SE3& T = odo.relative[static_cast<std::size_t>(i)];
    const Vec6 sigma = sigmas(0.05, 0.01);
    edges.push_back(
        {i, i + 1, T, correlated ? correlatedSqrtInformation(sigma, rng) : Mat6(sigma.cwiseInverse().asDiagonal())});
    if (correlated)
      g.addEdge(i, i + 1, T, edges.back().W);
    else
      g.addEdge(i, i + 1, T, sigma);
  }
  for (int i = 0; i + 10 < n; i += 7) {  // loop edges everywhere, with noise: no graph without tension
    const SE3 T = truth[static_cast<std::size_t>(i + 10)].inverse() * truth[static_cast<std::size_t>(i)] *
                  SE3::exp(Vec6::Constant(0.01));
    const Vec6 sigma = sigmas(0.03, 0.005);
    edges.push_back({i + 10, i, T, Mat6(sigma.cwiseInverse().asDiagonal())});
    g.addEdge(i + 10, i, T, sigma);
  }
  PoseGraphOptions options;
  options.max_iterations = 100;
  options.function_tolerance = 1e-16;
  const PoseGraphSummary summary = g.optimize(options);
  const double optimum = statedCost(g, edges);
  EXPECT_NEAR(summary.final_cost, optimum, 1e-9 * (1 + optimum));
  const double h = 1e-5;
  for (int node = 1; node < n; node += 5) {
    for (int k = 0; k < 6; ++k) {
      const SE3 T = g.pose(node);
      Vec6 d = Vec6::Zero();
      d[k] = h;
      g.setPose(node, T * SE3::exp(d));
      const double plus = statedCost(g, edges);
      g.setPose(node, T * SE3::exp(-d));
      const double minus = statedCost(g, edges);
      g.setPose(node, T);
      const double gradient = (plus - minus) / (2 * h);
      EXPECT_LT(std::abs(gradient), 1e-3 * (1 + optimum)) << "node " << node << " direction " << k;
    }
  }
}

TEST(PoseGraph, TheOptimumIsAStationaryPointOfTheCost) { expectTheOptimumIsStationary(/*correlated=*/false); }

TEST(PoseGraph, TheOptimumIsAStationaryPointOfTheCostAlsoWithCorrelatedUncertainties) {
  expectTheOptimumIsStationary(/*correlated=*/true);
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

// A monocular odometry around the circle: its unit grows by `scale_drift` per step (a distance of 1 m near node i
// measures (1 + scale_drift)^i map units), with a little noise.
struct ScaleDrift {
  std::vector<Sim3> relative;  // S_i_i+1 measured: the motion in the local unit, scale 1 (the odometry sees none)
  std::vector<SE3> chained;    // poses by chaining them from the first
  std::vector<double> unit;    // true map units per metre at each node
};

ScaleDrift scaleDrifting(const std::vector<SE3>& truth, double scale_drift, double noise, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0, noise);
  ScaleDrift o;
  o.chained.push_back(truth[0]);
  o.unit.push_back(1.0);
  for (std::size_t i = 0; i + 1 < truth.size(); ++i) {
    SE3 rel = truth[i].inverse() * truth[i + 1];
    rel.t *= o.unit.back();
    Vec6 err;
    err << n(rng), n(rng), n(rng), n(rng) * 0.1, n(rng) * 0.1, n(rng) * 0.1;
    rel = rel * SE3::exp(err);
    o.relative.emplace_back(rel);
    o.chained.push_back(o.chained.back() * rel);
    o.unit.push_back(o.unit.back() * (1 + scale_drift));
  }
  return o;
}

Vec7 similaritySigmas(double translation, double rotation, double log_scale) {
  Vec7 s;
  s << translation, translation, translation, rotation, rotation, rotation, log_scale;
  return s;
}

// The loop edge a place recognition measures between the last node and the first: each node's local frame in its
// own unit, so the similarity carries the ratio of the units.
Sim3 trueSimilarity(const std::vector<SE3>& truth, const ScaleDrift& odo, std::size_t a, std::size_t b) {
  const Sim3 S_w_a(truth[a], 1.0 / odo.unit[a]);
  const Sim3 S_w_b(truth[b], 1.0 / odo.unit[b]);
  return S_w_a.inverse() * S_w_b;
}

template <class Graph>
double positionRmseOf(const Graph& g, const std::vector<SE3>& truth) {
  double s = 0;
  for (int i = 0; i < g.nodes(); ++i) s += (g.pose(i).t - truth[static_cast<std::size_t>(i)].t).squaredNorm();
  return std::sqrt(s / g.nodes());
}

TEST(SimilarityPoseGraph, ALoopEdgeTakesTheScaleDriftOut) {
  const int n = 200;
  const auto truth = circle(n);
  const ScaleDrift odo = scaleDrifting(truth, 0.003, 0.002, 11);  // 1.8 times the unit at the end of the loop
  SimilarityPoseGraph sim(256, 512);
  PoseGraph rigid(256, 512);
  for (int i = 0; i < n; ++i) {
    sim.addNode(Sim3(odo.chained[static_cast<std::size_t>(i)]), i == 0);
    rigid.addNode(odo.chained[static_cast<std::size_t>(i)], i == 0);
  }
  for (int i = 0; i + 1 < n; ++i) {
    const Sim3& rel = odo.relative[static_cast<std::size_t>(i)];
    sim.addEdge(i, i + 1, rel, similaritySigmas(0.02, 0.002, 0.01));
    rigid.addEdge(i, i + 1, rel.rigid(), sigmas(0.02, 0.002));
  }
  const double before = positionRmseOf(sim, truth);
  const Sim3 loop = trueSimilarity(truth, odo, n - 1, 0);
  sim.addEdge(n - 1, 0, loop, similaritySigmas(0.01, 0.001, 0.01));
  rigid.addEdge(n - 1, 0, loop.rigid(), sigmas(0.01, 0.001));
  const PoseGraphSummary s = sim.optimize();
  ASSERT_TRUE(s.solved);
  rigid.optimize();
  const double after = positionRmseOf(sim, truth);
  const double rigid_after = positionRmseOf(rigid, truth);
  EXPECT_GT(before, 2.0);
  EXPECT_LT(after, 0.1 * before);
  EXPECT_LT(after, 0.25 * rigid_after);  // a rigid graph bends the loop closed but keeps the wrong unit
  // Each node's scale took the unit it was measured in: metres per map unit.
  for (int i = 0; i < n; i += 20)
    EXPECT_NEAR(sim.pose(i).s * odo.unit[static_cast<std::size_t>(i)], 1.0, 0.05) << "node " << i;
  EXPECT_EQ(sim.pose(0).s, 1.0);  // the fixed node
}

TEST(SimilarityPoseGraph, TheOptimumIsAStationaryPointOfTheCost) {
  const int n = 60;
  const auto truth = circle(n);
  const ScaleDrift odo = scaleDrifting(truth, 0.01, 0.01, 13);
  SimilarityPoseGraph g(64, 256);
  for (int i = 0; i < n; ++i) g.addNode(Sim3(odo.chained[static_cast<std::size_t>(i)]), i == 0);
  for (int i = 0; i + 1 < n; ++i)
    g.addEdge(i, i + 1, odo.relative[static_cast<std::size_t>(i)], similaritySigmas(0.05, 0.01, 0.02));
  for (int i = 0; i + 10 < n; i += 7)
    g.addEdge(i + 10, i,
              trueSimilarity(truth, odo, static_cast<std::size_t>(i + 10), static_cast<std::size_t>(i)) *
                  Sim3::exp(Vec7::Constant(0.01)),
              similaritySigmas(0.03, 0.005, 0.01));
  PoseGraphOptions options;
  options.max_iterations = 100;
  options.function_tolerance = 1e-16;
  g.optimize(options);
  const auto cost = [&] {
    double c = 0;
    for (int e = 0; e < g.edges(); ++e) c += 0.5 * g.residual(e).squaredNorm();
    return c;
  };
  const double optimum = cost();
  const double h = 1e-5;
  for (int node = 1; node < n; node += 5) {
    for (int k = 0; k < 7; ++k) {
      const Sim3 S = g.pose(node);
      Vec7 d = Vec7::Zero();
      d[k] = h;
      g.setPose(node, S * Sim3::exp(d));
      const double plus = cost();
      g.setPose(node, S * Sim3::exp(-d));
      const double minus = cost();
      g.setPose(node, S);
      EXPECT_LT(std::abs((plus - minus) / (2 * h)), 1e-3 * (1 + optimum)) << "node " << node << " direction " << k;
    }
  }
}

TEST(SimilarityPoseGraph, OptimizingAllocatesNothing) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  const int n = 200;
  const auto truth = circle(n);
  const ScaleDrift odo = scaleDrifting(truth, 0.003, 0.002, 17);
  SimilarityPoseGraph g(n, 2 * n);
  for (int i = 0; i < n; ++i) g.addNode(Sim3(odo.chained[static_cast<std::size_t>(i)]), i == 0);
  for (int i = 0; i + 1 < n; ++i)
    g.addEdge(i, i + 1, odo.relative[static_cast<std::size_t>(i)], similaritySigmas(0.02, 0.002, 0.01));
  g.addEdge(n - 1, 0, trueSimilarity(truth, odo, n - 1, 0), similaritySigmas(0.01, 0.001, 0.01));
  alloc::ThreadScope scope;
  const PoseGraphSummary s = g.optimize();
  EXPECT_TRUE(s.solved);
  EXPECT_EQ(scope.count(), 0u);
}

}  // namespace
}  // namespace mcslam::backend
