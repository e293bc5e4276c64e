#include "mcslam/backend/pose_graph.hpp"

#include "mcslam/backend/levenberg_marquardt.hpp"
#include "sparse_block_solver.hpp"

namespace mcslam::backend {

namespace {

// ad(xi) of se(3) in [rho; phi] order: [phi^ rho^; 0 phi^].
Mat6 smallAdjoint(const Vec6& xi) {
  Mat6 ad = Mat6::Zero();
  ad.topLeftCorner<3, 3>() = hat(xi.tail<3>());
  ad.topRightCorner<3, 3>() = hat(xi.head<3>());
  ad.bottomRightCorner<3, 3>() = hat(xi.tail<3>());
  return ad;
}

// Inverse right Jacobian of SE(3) to second order: exact enough for the residuals a pose graph meets (a loop
// closure's first residual included: the linearization is redone at every step).
Mat6 rightJacobianInverse(const Vec6& r) { return Mat6::Identity() + 0.5 * smallAdjoint(r); }

Vec6 edgeError(const SE3& inverse_measurement, const SE3& T_a, const SE3& T_b) {
  return (inverse_measurement * T_a.inverse() * T_b).log();
}

}  // namespace

// The least-squares problem over the free nodes: variable v is node node_of_[v].
class PoseGraph::Problem final : public LeastSquaresProblem {
 public:
  Problem(PoseGraph& graph, int max_nodes, int max_edges)
      : graph_(graph),
        solver_(max_nodes, max_edges),
        variable_of_(static_cast<std::size_t>(max_nodes)),
        node_of_(static_cast<std::size_t>(max_nodes)),
        pairs_(static_cast<std::size_t>(max_edges)),
        pair_of_edge_(static_cast<std::size_t>(max_edges), -1),
        entry_of_pair_(static_cast<std::size_t>(max_edges)),
        undamped_(static_cast<std::size_t>(max_nodes)),
        g_(static_cast<std::size_t>(6 * max_nodes)),
        dx_(static_cast<std::size_t>(6 * max_nodes)),
        rhs_(static_cast<std::size_t>(6 * max_nodes)),
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
    std::fill(g_.begin(), g_.begin() + 6 * variables_, 0.0);
    cost_ = 0;
    for (int e = 0; e < graph_.edges_; ++e) {
      const auto se = static_cast<std::size_t>(e);
      const int a = graph_.edge_a_[se], b = graph_.edge_b_[se];
      const int va = variable_of_[static_cast<std::size_t>(a)], vb = variable_of_[static_cast<std::size_t>(b)];
      const SE3& T_a = graph_.pose(a);
      const SE3& T_b = graph_.pose(b);
      const Vec6 r = edgeError(graph_.edge_inverse_measurement_[se], T_a, T_b);
      const Vec6& w = graph_.edge_weight_[se];
      const Vec6 wr = w.cwiseProduct(r);
      cost_ += 0.5 * wr.squaredNorm();
      if (va < 0 && vb < 0) continue;
      const Mat6 Jb = w.asDiagonal() * rightJacobianInverse(r);
      const Mat6 Ja = -Jb * (T_b.inverse() * T_a).adjoint();
      if (va >= 0) addBlock(va, Ja, wr);
      if (vb >= 0) addBlock(vb, Jb, wr);
      if (va >= 0 && vb >= 0 && va != vb) {
        const int entry = entry_of_pair_[static_cast<std::size_t>(pair_of_edge_[se])];
        const bool a_low = solver_.entryLow(entry) == va;
        solver_.offDiagonal(entry) += a_low ? Mat6(Ja.transpose() * Jb) : Mat6(Jb.transpose() * Ja);
      }
    }
    for (int v = 0; v < variables_; ++v) undamped_[static_cast<std::size_t>(v)] = solver_.diagonal(v);
    return std::isfinite(cost_);
  }

  double cost() const override { return cost_; }

  void buildDampedSystem(double mu) override {
    mu_ = mu;
    for (int v = 0; v < variables_; ++v) {
      Mat6& D = solver_.diagonal(v);
      D = undamped_[static_cast<std::size_t>(v)];
      for (int k = 0; k < 6; ++k) D(k, k) += mu * dampingDiagonal(D(k, k));
    }
  }

  double maxGradient() const override {
    double m = 0;
    for (int i = 0; i < 6 * variables_; ++i) m = std::max(m, std::abs(g_[static_cast<std::size_t>(i)]));
    return m;
  }

  bool solveStep() override {
    for (int i = 0; i < 6 * variables_; ++i) rhs_[static_cast<std::size_t>(i)] = -g_[static_cast<std::size_t>(i)];
    if (!solver_.solve(rhs_.data(), dx_.data())) return false;
    for (int i = 0; i < 6 * variables_; ++i)
      if (!std::isfinite(dx_[static_cast<std::size_t>(i)])) return false;
    return true;
  }

  double stepNorm() const override {
    double s = 0;
    for (int i = 0; i < 6 * variables_; ++i) s += dx_[static_cast<std::size_t>(i)] * dx_[static_cast<std::size_t>(i)];
    return std::sqrt(s);
  }

  // -(g dx + dx H dx / 2) with H dx = -g - mu D dx.
  double modelCostDecrease(double mu) const override {
    double gdx = 0, ddx = 0;
    for (int v = 0; v < variables_; ++v) {
      const Mat6& H = undamped_[static_cast<std::size_t>(v)];
      for (int k = 0; k < 6; ++k) {
        const auto i = static_cast<std::size_t>(6 * v + k);
        gdx += g_[i] * dx_[i];
        ddx += dampingDiagonal(H(k, k)) * dx_[i] * dx_[i];
      }
    }
    return 0.5 * (-gdx + mu * ddx);
  }

  bool evaluateTrial(double& cost) override {
    for (int v = 0; v < variables_; ++v) {
      Vec6 step;
      for (int k = 0; k < 6; ++k) step[k] = dx_[static_cast<std::size_t>(6 * v + k)];
      trial_[static_cast<std::size_t>(v)] = graph_.pose(node_of_[static_cast<std::size_t>(v)]) * SE3::exp(step);
    }
    cost = 0;
    for (int e = 0; e < graph_.edges_; ++e) {
      const auto se = static_cast<std::size_t>(e);
      const Vec6 r =
          edgeError(graph_.edge_inverse_measurement_[se], trialPose(graph_.edge_a_[se]), trialPose(graph_.edge_b_[se]));
      cost += 0.5 * graph_.edge_weight_[se].cwiseProduct(r).squaredNorm();
    }
    return std::isfinite(cost);
  }

  void acceptTrial() override {
    for (int v = 0; v < variables_; ++v) {
      SE3& T = graph_.poses_[static_cast<std::size_t>(node_of_[static_cast<std::size_t>(v)])];
      T = trial_[static_cast<std::size_t>(v)];
      T.normalize();
    }
  }

  int analyses() const { return solver_.analyses(); }

 private:
  void addBlock(int v, const Mat6& J, const Vec6& wr) {
    solver_.diagonal(v) += J.transpose() * J;
    const Vec6 gv = J.transpose() * wr;
    for (int k = 0; k < 6; ++k) g_[static_cast<std::size_t>(6 * v + k)] += gv[k];
  }
  const SE3& trialPose(int node) const {
    const int v = variable_of_[static_cast<std::size_t>(node)];
    return v < 0 ? graph_.pose(node) : trial_[static_cast<std::size_t>(v)];
  }

  PoseGraph& graph_;
  SparseBlockSolver solver_;
  std::vector<int32_t> variable_of_, node_of_;
  std::vector<BlockPair> pairs_;
  std::vector<int32_t> pair_of_edge_, entry_of_pair_;
  std::vector<Mat6> undamped_;
  std::vector<double> g_, dx_, rhs_;
  std::vector<SE3> trial_;
  int variables_ = 0;
  double cost_ = 0, mu_ = 0;
};

PoseGraph::PoseGraph(int max_nodes, int max_edges)
    : poses_(static_cast<std::size_t>(max_nodes)),
      fixed_(static_cast<std::size_t>(max_nodes), 0),
      edge_a_(static_cast<std::size_t>(max_edges)),
      edge_b_(static_cast<std::size_t>(max_edges)),
      edge_inverse_measurement_(static_cast<std::size_t>(max_edges)),
      edge_weight_(static_cast<std::size_t>(max_edges)),
      problem_(std::make_unique<Problem>(*this, max_nodes, max_edges)) {}

PoseGraph::~PoseGraph() = default;

void PoseGraph::clear() { nodes_ = edges_ = 0; }

int PoseGraph::addNode(const SE3& T_w_n, bool fixed) {
  if (nodes_ == maxNodes()) return -1;
  poses_[static_cast<std::size_t>(nodes_)] = T_w_n;
  fixed_[static_cast<std::size_t>(nodes_)] = fixed ? 1 : 0;
  return nodes_++;
}

bool PoseGraph::addEdge(int a, int b, const SE3& T_a_b, const Vec6& sigma) {
  if (edges_ == maxEdges() || a < 0 || b < 0 || a >= nodes_ || b >= nodes_) return false;
  const auto e = static_cast<std::size_t>(edges_++);
  edge_a_[e] = a;
  edge_b_[e] = b;
  edge_inverse_measurement_[e] = T_a_b.inverse();
  edge_weight_[e] = sigma.cwiseInverse();
  return true;
}

void PoseGraph::setFixed(int n, bool fixed) { fixed_[static_cast<std::size_t>(n)] = fixed ? 1 : 0; }

Vec6 PoseGraph::residual(int e) const {
  const auto se = static_cast<std::size_t>(e);
  return edge_weight_[se].cwiseProduct(edgeError(edge_inverse_measurement_[se], pose(edge_a_[se]), pose(edge_b_[se])));
}

PoseGraphSummary PoseGraph::optimize(const PoseGraphOptions& options) {
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

}  // namespace mcslam::backend
