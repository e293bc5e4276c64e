#pragma once
// A pose graph: nodes are poses T_w_n (the place map's keyframes), edges are measured relative poses between two
// nodes (consecutive keyframes by the odometry; a recognized place by loop closure) with its uncertainty: a standard
// deviation per tangent direction, or a square-root information matrix when the directions are correlated (an
// odometry whose unit is uncertain knows its direction of travel better than its length). optimize() moves the free
// nodes to agree with every edge in the least-squares sense (residual log(T_ab^-1 T_a^-1 T_b), right perturbations),
// Levenberg-Marquardt over a sparse CHOLMOD factorization. The poses are SE(3) (PoseGraph: a metric map) or Sim(3)
// (SimilarityPoseGraph: a map whose unit drifts, whose loops measure a scale too). Capacities are fixed at
// construction; adding, optimizing and reading allocate nothing.
#include <memory>
#include <vector>

#include "mcslam/core/se3.hpp"
#include "mcslam/core/sim3.hpp"

namespace mcslam::backend {

struct PoseGraphOptions {
  int max_iterations = 30;            // Levenberg-Marquardt steps
  double function_tolerance = 1e-12;  // relative cost decrease that ends it
};

struct PoseGraphSummary {
  bool solved = false;  // at least one step was taken or the graph was already consistent
  int iterations = 0;
  double initial_cost = 0, final_cost = 0;  // 0.5 * sum of whitened squared residuals
  int analyses = 0;                         // symbolic analyses so far (one per change of structure)
};

template <class Pose>
class PoseGraphT {
 public:
  using Tangent = typename Pose::Tangent;
  using Jacobian = typename Pose::Jacobian;

  PoseGraphT(int max_nodes, int max_edges);
  ~PoseGraphT();
  PoseGraphT(const PoseGraphT&) = delete;
  PoseGraphT& operator=(const PoseGraphT&) = delete;

  void clear();
  // Index of the new node, -1 when full. A fixed node keeps its pose (one per connected part fixes its gauge).
  int addNode(const Pose& T_w_n, bool fixed);
  // Edge measuring T_a_b = T_w_a^-1 T_w_b, with standard deviations per tangent direction ([rho (m); phi (rad)],
  // then log scale for Sim(3)). False when full.
  bool addEdge(int a, int b, const Pose& T_a_b, const Tangent& sigma);
  // The same with a square-root information W (W^T W is the inverse covariance of the tangent residual).
  bool addEdge(int a, int b, const Pose& T_a_b, const Jacobian& sqrt_information);

  int nodes() const { return nodes_; }
  int edges() const { return edges_; }
  int maxNodes() const { return static_cast<int>(poses_.size()); }
  int maxEdges() const { return static_cast<int>(edge_a_.size()); }
  const Pose& pose(int n) const { return poses_[static_cast<std::size_t>(n)]; }
  void setPose(int n, const Pose& T_w_n) { poses_[static_cast<std::size_t>(n)] = T_w_n; }
  bool fixed(int n) const { return fixed_[static_cast<std::size_t>(n)] != 0; }
  void setFixed(int n, bool fixed);
  // Whitened residual of edge e at the current poses.
  Tangent residual(int e) const;

  PoseGraphSummary optimize(const PoseGraphOptions& options = {});

 private:
  class Problem;
  friend class Problem;

  std::vector<Pose> poses_;
  std::vector<uint8_t> fixed_;
  std::vector<int32_t> edge_a_, edge_b_;
  std::vector<Pose> edge_inverse_measurement_;  // T_a_b^-1
  std::vector<Jacobian> edge_weight_;           // square-root information: whitened residual = W r
  int nodes_ = 0, edges_ = 0;
  std::unique_ptr<Problem> problem_;
};

extern template class PoseGraphT<SE3>;
extern template class PoseGraphT<Sim3>;
using PoseGraph = PoseGraphT<SE3>;
using SimilarityPoseGraph = PoseGraphT<Sim3>;

}  // namespace mcslam::backend
