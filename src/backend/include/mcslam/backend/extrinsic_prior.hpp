#pragma once
// Prior of an extrinsic T_b_c on its calibrated value, whitened by the calibration sigmas:
//
//   r = [ R_cal^T (t - t_cal) / sigma_t ;  log(R_cal^T R) / sigma_r ]
//
// Translation and rotation are decoupled so the Jacobian for the right perturbation T * exp(e)
// is exact and block diagonal: [R_cal^T R / sigma_t, 0; 0, Jr^-1(log(R_cal^T R)) / sigma_r].
#include "mcslam/core/se3.hpp"

namespace mcslam::backend {

struct ExtrinsicPriorSigmas {
  double translation = 0.01;             // metres
  double rotation = 1.0 * M_PI / 180.0;  // radians
};

// Residual at T; Jacobian (optional) evaluated at T_jac (the first estimate when the extrinsic is
// linked to the marginalization prior, otherwise T itself).
inline Vec6 extrinsicPriorResidual(const SE3& T_calib, const SE3& T, const ExtrinsicPriorSigmas& sigmas,
                                   const SE3* T_jac = nullptr, Mat6* J = nullptr) {
  Vec6 r;
  r.head<3>() = T_calib.R.transpose() * (T.t - T_calib.t) / sigmas.translation;
  r.tail<3>() = so3Log(T_calib.R.transpose() * T.R) / sigmas.rotation;
  if (J) {
    const SE3& Tj = T_jac ? *T_jac : T;
    const Mat3 dR = T_calib.R.transpose() * Tj.R;
    J->setZero();
    J->topLeftCorner<3, 3>() = dR / sigmas.translation;
    // Jr^-1(w) = Jl^-1(-w)
    J->bottomRightCorner<3, 3>() = so3LeftJacobianInverse(-so3Log(dR)) / sigmas.rotation;
  }
  return r;
}

}  // namespace mcslam::backend
