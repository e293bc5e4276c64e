#include "mcslam/backend/pose_graph.hpp"

#include "mcslam/backend/levenberg_marquardt.hpp"
#include "sparse_block_solver.hpp"

namespace mcslam::backend {

namespace {

// Inverse right Jacobian to second order: exact enough for the residuals a pose graph meets (a loop closure's
// first residual included: the linearization is redone at every step).
template <class Pose>
typename Pose::Jacobian rightJacobianInverse(const typename Pose::Tangent& r) {
  return Pose::Jacobian::Identity() + 0.5 * Pose::smallAdjoint(r);
}

template <class Pose>
typename Pose::Tangent edgeError(const Pose& inverse_measurement, const Pose& T_a, const Pose& T_b) {
  return (inverse_measurement * T_a.inverse() * T_b).log();
}

}  // namespace

// The least-squares problem over the free nodes: variable v is node node_of_[v].
template <class Pose>
class PoseGraphT<Pose>::Problem final : public LeastSquaresProblem {
  static constexpr int D = Pose::kDof;
  using Tangent = typename Pose::Tangent;
  using Jacobian = typename Pose::Jacobian;

 public:
  Problem(PoseGraphT& graph, int max_nodes, int max_edges)
      : graph_(graph),
        solver_(max_nodes, max_edges),
        variable_of_(static_cast<std::size_t>(max_nodes)),
        node_of_(static_cast<std::size_t>(max_nodes)),
        pairs_(static_cast<std::size_t>(max_edges)),
        pair_of_edge_(static_cast<std::size_t>(max_edges), -1),
        entry_of_pair_(static_cast<std::size_t>(max_edges)),
        undamped_(static_cast<std::size_t>(max_nodes)),
        g_(static_cast<std::size_t>(D * max_nodes)),
        dx_(static_cast<std::size_t>(D * max_nodes)),
        rhs_(static_cast<std::size_t>(D * max_nodes)),
        trial_(static_cast<std::size_t>(max_nodes)) {}

  // Variables and the block structure of the current graph; false when nothing is free.
  bool setUp() {
    variables_ = 0;
    for (int n = 0; n < graph_.nodes_; ++n) {
      variable_of_[static_cast<std::size_t>(n)] = graph_.fixed(n) ? -1 : variables_;
      if (!graph_.fixed(n)) node_of_[static_cast<std::size_t>(variables_++)] = n;
    }
    if (variables_ == 0) return false;
    int pairs = 0;
    for (int e = 0; e < graph_.edges_; ++e) {
      const int va = variable_of_[static_cast<std::size_t>(graph_.edge_a_[static_cast<std::size_t>(e)])];
      const int vb = variable_of_[static_cast<std::size_t>(graph_.edge_b_[static_cast<std::size_t>(e)])];
      pair_of_edge_[static_cast<std::size_t>(e)] = -1;
      if (va < 0 || vb < 0 || va == vb) continue;
      pair_of_edge_[static_cast<std::size_t>(e)] = pairs;
      pairs_[static_cast<std::size_t>(pairs++)] = {va, vb};
    }
    solver_.setStructure(variables_, std::span(pairs_.data(), static_cast<std::size_t>(pairs)), entry_of_pair_);
    return true;
  }

  bool linearize() override {
    solver_.setZero();
    std::fill(g_.begin(), g_.begin() + D * variables_, 0.0);
    cost_ = 0;
    for (int e = 0; e < graph_.edges_; ++e) {
      const auto se = static_cast<std::size_t>(e);
      const int a = graph_.edge_a_[se], b = graph_.edge_b_[se];
      const int va = variable_of_[static_cast<std::size_t>(a)], vb = variable_of_[static_cast<std::size_t>(b)];
      const Pose& T_a = graph_.pose(a);
      const Pose& T_b = graph_.pose(b);
      const Tangent r = edgeError(graph_.edge_inverse_measurement_[se], T_a, T_b);
      const Jacobian& W = graph_.edge_weight_[se];
      const Tangent wr = W * r;
      cost_ += 0.5 * wr.squaredNorm();
      if (va < 0 && vb < 0) continue;
      const Jacobian Jb = W * rightJacobianInverse<Pose>(r);
      const Jacobian Ja = -Jb * (T_b.inverse() * T_a).adjoint();
      if (va >= 0) addBlock(va, Ja, wr);
      if (vb >= 0) addBlock(vb, Jb, wr);
      if (va >= 0 && vb >= 0 && va != vb) {
        const int entry = entry_of_pair_[static_cast<std::size_t>(pair_of_edge_[se])];
        const bool a_low = solver_.entryLow(entry) == va;
        solver_.offDiagonal(entry) += a_low ? Jacobian(Ja.transpose() * Jb) : Jacobian(Jb.transpose() * Ja);
      }
    }
    for (int v = 0; v < variables_; ++v) undamped_[static_cast<std::size_t>(v)] = solver_.diagonal(v);
    return std::isfinite(cost_);
  }

  double cost() const override { return cost_; }

  void buildDampedSystem(double mu) override {
    mu_ = mu;
    for (int v = 0; v < variables_; ++v) {
      Jacobian& H = solver_.diagonal(v);
      H = undamped_[static_cast<std::size_t>(v)];
      for (int k = 0; k < D; ++k) H(k, k) += mu * dampingDiagonal(H(k, k));
    }
  }

  double maxGradient() const override {
    double m = 0;
    for (int i = 0; i < D * variables_; ++i) m = std::max(m, std::abs(g_[static_cast<std::size_t>(i)]));
    return m;
  }

  bool solveStep() override {
    for (int i = 0; i < D * variables_; ++i) rhs_[static_cast<std::size_t>(i)] = -g_[static_cast<std::size_t>(i)];
    if (!solver_.solve(rhs_.data(), dx_.data())) return false;
    for (int i = 0; i < D * variables_; ++i)
      if (!std::isfinite(dx_[static_cast<std::size_t>(i)])) return false;
    return true;
  }

  double stepNorm() const override {
    double s = 0;
    for (int i = 0; i < D * variables_; ++i) s += dx_[static_cast<std::size_t>(i)] * dx_[static_cast<std::size_t>(i)];
    return std::sqrt(s);
  }

  // -(g dx + dx H dx / 2) with H dx = -g - mu D dx.
  double modelCostDecrease(double mu) const override {
    double gdx = 0, ddx = 0;
    for (int v = 0; v < variables_; ++v) {
      const Jacobian& H = undamped_[static_cast<std::size_t>(v)];
      for (int k = 0; k < D; ++k) {
        const auto i = static_cast<std::size_t>(D * v + k);
        gdx += g_[i] * dx_[i];
        ddx += dampingDiagonal(H(k, k)) * dx_[i] * dx_[i];
      }
    }
    return 0.5 * (-gdx + mu * ddx);
  }

  bool evaluateTrial(double& cost) override {
    for (int v = 0; v < variables_; ++v) {
      Tangent step;
      for (int k = 0; k < D; ++k) step[k] = dx_[static_cast<std::size_t>(D * v + k)];
      trial_[static_cast<std::size_t>(v)] = graph_.pose(node_of_[static_cast<std::size_t>(v)]) * Pose::exp(step);
    }
    cost = 0;
    for (int e = 0; e < graph_.edges_; ++e) {
      const auto se = static_cast<std::size_t>(e);
      const Tangent r =
          edgeError(graph_.edge_inverse_measurement_[se], trialPose(graph_.edge_a_[se]), trialPose(graph_.edge_b_[se]));
      cost += 0.5 * (graph_.edge_weight_[se] * r).squaredNorm();
    }
    return std::isfinite(cost);
  }

  void acceptTrial() override {
    for (int v = 0; v < variables_; ++v) {
      Pose& T = graph_.poses_[static_cast<std::size_t>(node_of_[static_cast<std::size_t>(v)])];
      T = trial_[static_cast<std::size_t>(v)];
      T.normalize();
    }
  }

  int analyses() const { return solver_.analyses(); }

 private:
  void addBlock(int v, const Jacobian& J, const Tangent& wr) {
    solver_.diagonal(v) += J.transpose() * J;
    const Tangent gv = J.transpose() * wr;
    for (int k = 0; k < D; ++k) g_[static_cast<std::size_t>(D * v + k)] += gv[k];
  }
  const Pose& trialPose(int node) const {
    const int v = variable_of_[static_cast<std::size_t>(node)];
    return v < 0 ? graph_.pose(node) : trial_[static_cast<std::size_t>(v)];
  }

  PoseGraphT& graph_;
  SparseBlockSolver<D> solver_;
  std::vector<int32_t> variable_of_, node_of_;
  std::vector<BlockPair> pairs_;
  std::vector<int32_t> pair_of_edge_, entry_of_pair_;
  std::vector<Jacobian> undamped_;
  std::vector<double> g_, dx_, rhs_;
  std::vector<Pose> trial_;
  int variables_ = 0;
  double cost_ = 0, mu_ = 0;
};

template <class Pose>
PoseGraphT<Pose>::PoseGraphT(int max_nodes, int max_edges)
    : poses_(static_cast<std::size_t>(max_nodes)),
      fixed_(static_cast<std::size_t>(max_nodes), 0),
      edge_a_(static_cast<std::size_t>(max_edges)),
      edge_b_(static_cast<std::size_t>(max_edges)),
      edge_inverse_measurement_(static_cast<std::size_t>(max_edges)),
      edge_weight_(static_cast<std::size_t>(max_edges)),
      problem_(std::make_unique<Problem>(*this, max_nodes, max_edges)) {}

template <class Pose>
PoseGraphT<Pose>::~PoseGraphT() = default;

template <class Pose>
void PoseGraphT<Pose>::clear() {
  nodes_ = edges_ = 0;
}

template <class Pose>
int PoseGraphT<Pose>::addNode(const Pose& T_w_n, bool fixed) {
  if (nodes_ == maxNodes()) return -1;
  poses_[static_cast<std::size_t>(nodes_)] = T_w_n;
  fixed_[static_cast<std::size_t>(nodes_)] = fixed ? 1 : 0;
  return nodes_++;
}

template <class Pose>
bool PoseGraphT<Pose>::addEdge(int a, int b, const Pose& T_a_b, const Tangent& sigma) {
  return addEdge(a, b, T_a_b, Jacobian(sigma.cwiseInverse().asDiagonal()));
}

template <class Pose>
bool PoseGraphT<Pose>::addEdge(int a, int b, const Pose& T_a_b, const Jacobian& sqrt_information) {
  if (edges_ == maxEdges() || a < 0 || b < 0 || a >= nodes_ || b >= nodes_) return false;
  const auto e = static_cast<std::size_t>(edges_++);
  edge_a_[e] = a;
  edge_b_[e] = b;
  edge_inverse_measurement_[e] = T_a_b.inverse();
  edge_weight_[e] = sqrt_information;
  return true;
}

template <class Pose>
void PoseGraphT<Pose>::setFixed(int n, bool fixed) {
  fixed_[static_cast<std::size_t>(n)] = fixed ? 1 : 0;
}

template <class Pose>
typename PoseGraphT<Pose>::Tangent PoseGraphT<Pose>::residual(int e) const {
  const auto se = static_cast<std::size_t>(e);
  return edge_weight_[se] * edgeError(edge_inverse_measurement_[se], pose(edge_a_[se]), pose(edge_b_[se]));
}

template <class Pose>
PoseGraphSummary PoseGraphT<Pose>::optimize(const PoseGraphOptions& options) {
  PoseGraphSummary summary;
  if (!problem_->setUp()) return summary;
  LoopOptions loop;
  loop.damping = DampingPolicy::trustRegion(1e4);
  loop.max_steps = options.max_iterations;
  loop.max_solves = 4 * options.max_iterations;
  loop.function_tolerance = options.function_tolerance;
  loop.max_consecutive_rejections = 10;
  const LoopSummary s = minimize(*problem_, loop);
  summary.solved = !s.failed;
  summary.iterations = s.steps;
  summary.initial_cost = s.initial_cost;
  summary.final_cost = s.final_cost;
  summary.analyses = problem_->analyses();
  return summary;
}

template class PoseGraphT<SE3>;
template class PoseGraphT<Sim3>;

}  // namespace mcslam::backend
