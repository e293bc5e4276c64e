#pragma once
// Quadratic prior left by marginalization, on the stacked perturbations d of the free extrinsics
// (T = T_lin * exp(d), 6 per free camera in camera order):
//
//   E(d) = c + b^T d + 0.5 d^T H d,   H symmetric positive semi-definite.
//
// Its linearization point (each extrinsic's T_lin) never moves once the extrinsic is linked.
#include <Eigen/Core>

namespace mcslam::backend {

struct MarginalizationPrior {
  Eigen::MatrixXd H;
  Eigen::VectorXd b;
  double c = 0;
  bool empty = true;

  explicit MarginalizationPrior(int dim) : H(Eigen::MatrixXd::Zero(dim, dim)), b(Eigen::VectorXd::Zero(dim)) {}
  int dim() const { return static_cast<int>(b.size()); }
};

}  // namespace mcslam::backend
