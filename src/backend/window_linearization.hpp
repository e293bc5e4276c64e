#pragma once
// One Levenberg-Marquardt problem over the window: which variables are free (the gauge), which
// landmarks enter, the residuals and Jacobians at the current state, the damped reduced camera
// system after eliminating the landmarks (Schur complement on 3x3 blocks), the landmark
// back-substitution, and the cost at a trial step. Every buffer is sized at construction.
#include <cmath>

#include <Eigen/Core>
#include <vector>

#include <array>

#include "calibration_prior.hpp"
#include "marginalization_prior.hpp"
#include "mcslam/backend/schur_accumulator.hpp"
#include "window_scale_hold.hpp"
#include "window_storage.hpp"

namespace mcslam::backend {

class WindowLinearization {
 public:
  WindowLinearization(const WindowStorage& window, const SolverOptions& options);

  // Chooses the free variables (gauge: the `fixed_oldest` oldest keyframes and those the caller fixed are
  // held) and collects the landmarks with >= 2 observations. False when there is nothing to optimize.
  // `hold_scale`: SolverOptions::hold_window_scale (the reference distances are taken here).
  bool prepare(const WindowStorage& window, int fixed_oldest, bool hold_scale);
  // Residuals, robust weights and Jacobians at the current state. `select_landmarks` (first call
  // of a solve) drops observations that do not project and landmarks that are not constrained.
  void linearize(const WindowStorage& window, MarginalizationPrior& prior, bool select_landmarks);
  double cost() const { return cost_; }
  double maxGradient() const;

  // Damped reduced system (H_cc + mu D_c - W (H_ll + mu D_l)^-1 W^T) and its right-hand side.
  void buildReducedSystem(const WindowStorage& window, double mu, const MarginalizationPrior& prior);
  int numBlocks() const { return num_blocks_; }
  int maxBlocks() const { return max_blocks_; }
  const uint8_t* blockPattern() const { return pattern_.data(); }
  const double* reducedMatrix() const { return S_.data(); }  // leading dimension 6 * maxBlocks()
  const double* reducedRhs() const { return rhs_.data(); }
  double* cameraStep() { return dx_c_.data(); }

  // Landmark steps from the camera step in cameraStep(); then the predicted cost decrease and
  // the squared norms of the step and of the state (for the parameter tolerance).
  void backSubstitute();
  double modelCostDecrease(double mu) const;
  double stepSquaredNorm() const;
  double stateSquaredNorm(const WindowStorage& window) const;

  // Cost at state (+) step; false when an observation stops projecting there.
  bool evaluateTrial(const WindowStorage& window, const MarginalizationPrior& prior, double& cost);
  void commitTrial(WindowStorage& window) const;

  int landmarksUsed() const { return landmarks_used_; }
  int landmarksSkipped() const { return landmarks_skipped_; }
  int residualsUsed() const { return residuals_used_; }

 private:
  struct ObservationRef {
    int slot;
    int pose_block;  // -1: keyframe held fixed
    int ext_block;   // -1: extrinsic not refined
    bool active;
  };
  // Jacobians stored transposed (columns = residual rows), so that the J^T J and J^T J'
  // products of the reduced system run on contiguous 6-vectors (SIMD-friendly).
  struct ObservationLin {
    Vec2 r;                          // sqrt(weight) * whitened residual
    Eigen::Matrix<double, 6, 2> Jp;  // sqrt(weight) * (d r / d pose)^T
    Eigen::Matrix<double, 3, 2> Jl;  // ... landmark
  };
  using ExtrinsicJacobian = Eigen::Matrix<double, 6, 2>;  // ... extrinsic, in je_
  struct LandmarkLin {
    int slot;
    int begin, end;  // observation range
    bool active;
    Mat3 H_inv;  // (H_ll + mu D_l)^-1 of the last build
    Vec3 g;
    Vec3 D;
    Vec3 dx;
    Vec3 p_trial;
  };

  void updateTransforms(const WindowStorage& window);
  // The observations of landmark L at the current state; its cost and valid count, and its 3x3 information.
  double linearizeLandmark(const WindowStorage& window, LandmarkLin& L, bool select, int& valid, Mat3& H);
  // Adds landmark L's part to the reduced system (damped by mu) and eliminates it.
  void eliminateLandmark(LandmarkLin& L, double mu);
  WindowVariables variables(const WindowStorage& window) const;
  // The extra terms, in the order their costs are summed.
  std::array<WindowTerm*, 3> terms(MarginalizationPrior& prior) { return {&scale_hold_, &calibration_prior_, &prior}; }
  std::array<const WindowTerm*, 3> terms(const MarginalizationPrior& prior) const {
    return {&scale_hold_, &calibration_prior_, &prior};
  }
  double termsCost(const WindowStorage& window, const MarginalizationPrior& prior, bool trial) const;

  const SolverOptions options_;
  int max_blocks_;
  int ld_;
  int num_cameras_;

  // Variables of this solve.
  std::vector<int> pose_block_;  // per keyframe slot
  std::vector<int> ext_block_;   // per camera
  int num_blocks_ = 0;
  std::vector<SE3> T_b_w_;      // per keyframe slot
  std::vector<SE3> T_c_b_;      // per camera, current
  std::vector<SE3> T_c_b_jac_;  // per camera, where Jacobians are evaluated (first estimate)
  std::vector<uint8_t> use_fej_;

  std::vector<LandmarkLin> landmarks_;
  int num_landmarks_ = 0;
  std::vector<ObservationRef> refs_;
  std::vector<ObservationLin> lin_;
  // Per observation, parallel to lin_; only when an extrinsic is refined (otherwise no observation has
  // an extrinsic block and this would be a third of lin_'s memory, never read).
  std::vector<ExtrinsicJacobian> je_;
  int num_refs_ = 0;
  double cost_ = 0;
  int landmarks_used_ = 0, landmarks_skipped_ = 0, residuals_used_ = 0;
  CalibrationPrior calibration_prior_;
  WindowScaleHold scale_hold_;

  // Reduced camera system.
  Eigen::MatrixXd S_;
  Eigen::VectorXd g_c_;  // gradient of the camera variables (before elimination)
  Eigen::VectorXd D_c_;  // clamped diagonal of H_cc
  Eigen::VectorXd rhs_;  // -(reduced gradient)
  Eigen::VectorXd dx_c_;
  double max_gradient_ = 0;
  std::vector<uint8_t> pattern_;
  SchurAccumulator schur_;  // eliminates the landmarks

  // Trial state.
  std::vector<SE3> kf_trial_;
  std::vector<SE3> ext_trial_;
  std::vector<Vec6> ext_d_trial_;
};

}  // namespace mcslam::backend
