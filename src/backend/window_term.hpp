#pragma once
// A term of the window's cost besides the reprojections: a residual or a prior on the camera variables (free
// poses and extrinsics, 6x6 blocks of the reduced camera system). The window's linearization calls its terms
// in one fixed order; a new term is one class behind this interface and one line in window_linearization.cpp.
#include <cstdint>
#include <span>

#include <Eigen/Core>

#include "window_storage.hpp"

namespace mcslam::backend {

// What a term sees of one solve: the window at the current state, the blocks of the free variables, and the
// trial state of the step being tried. Valid for one call.
struct WindowVariables {
  const WindowStorage& window;
  std::span<const int> pose_block;    // per keyframe slot: block of its pose, < 0 when held
  std::span<const int> ext_block;     // per camera: block of its extrinsic, < 0 when not refined
  std::span<const uint8_t> use_fej;   // per camera: Jacobians at the extrinsic's first estimate
  std::span<const SE3> kf_trial;      // per keyframe slot, T_w_b at the trial step
  std::span<const SE3> ext_trial;     // per camera, T_b_c at the trial step
  std::span<const Vec6> ext_d_trial;  // per camera, its d (T = T_lin exp(d)) at the trial step
};

// The reduced camera system a term adds J^T J (upper blocks, marked in the pattern), the gradient J^T r and the
// diagonal of J^T J (Levenberg-Marquardt's scaling) to.
struct CameraSystem {
  Eigen::MatrixXd& S;
  Eigen::VectorXd& g;
  Eigen::VectorXd& D;
  uint8_t* pattern;  // row-major, `stride` blocks per row
  int stride;
  void mark(int a, int b) { pattern[static_cast<size_t>(a) * stride + b] = 1; }
};

class WindowTerm {
 public:
  virtual ~WindowTerm() = default;
  // Residuals and Jacobians at the current state.
  virtual void linearize(const WindowVariables& v) = 0;
  // Adds the cost at the current state, or at the trial state, to `cost`.
  virtual void addCost(const WindowVariables& v, bool trial, double& cost) const = 0;
  // Adds the linearization to the camera system.
  virtual void addToSystem(const WindowVariables& v, CameraSystem& system) const = 0;
};

}  // namespace mcslam::backend
