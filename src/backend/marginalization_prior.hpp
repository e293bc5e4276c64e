#pragma once
// Quadratic prior left by marginalization, on the stacked perturbations d of the free extrinsics
// (T = T_lin * exp(d), 6 per free camera in camera order):
//
//   E(d) = c + b^T d + 0.5 d^T H d,   H symmetric positive semi-definite.
//
// Its linearization point (each extrinsic's T_lin) never moves once the extrinsic is linked. The prior is state
// of the window (it outlives a solve); the marginalizer adds to it, the solves read it. Scratch sized at
// construction.
#include <Eigen/Core>
#include <vector>

#include "window_term.hpp"

namespace mcslam::backend {

class MarginalizationPrior final : public WindowTerm {
 public:
  explicit MarginalizationPrior(const WindowStorage& window);
  void clear();  // nothing known, as constructed
  int dim() const { return static_cast<int>(b.size()); }

  void linearize(const WindowVariables& v) override;
  void addCost(const WindowVariables& v, bool trial, double& cost) const override;
  void addToSystem(const WindowVariables& v, CameraSystem& system) const override;

  // Adds information gathered at the window's current d: E(d') += c + gn^T (d' - d) + 0.5 (d' - d)^T Hn (d' - d),
  // re-expressed around the fixed linearization point and kept symmetric positive semi-definite. The extrinsics
  // that received information are linked to the prior from now on.
  void absorb(const Eigen::MatrixXd& Hn, const Eigen::VectorXd& gn, double c, WindowStorage& window);
  // Marginalizes the camera's extrinsic out of the prior (what it told about the others stays) and unlinks it:
  // the estimate it was linearized at was judged wrong. Rare (an outside re-estimation): may allocate.
  void forgetExtrinsic(int camera, WindowStorage& window);

  Eigen::MatrixXd H;
  Eigen::VectorXd b;
  double c = 0;
  bool empty = true;

 private:
  void stackCurrent(const WindowStorage& window, Eigen::VectorXd& d) const;

  std::vector<int> ext_var_of_camera_;
  Eigen::VectorXd d_current_;       // stacked d at the linearization
  mutable Eigen::VectorXd d_eval_;  // stacked d where the cost is evaluated
  Eigen::VectorXd d_, tmp_;
  Eigen::MatrixXd scratch_, V_;
};

}  // namespace mcslam::backend
