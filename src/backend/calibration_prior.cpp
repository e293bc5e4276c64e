#include "calibration_prior.hpp"

namespace mcslam::backend {

void CalibrationPrior::linearize(const WindowVariables& v) {
  for (int c = 0; c < v.window.numCameras(); ++c) {
    const ExtrinsicState& e = v.window.extrinsics[c];
    if (!e.variable) continue;
    if (!e.calibration_prior) {
      r_[c].setZero();
      J_[c].setZero();
      continue;
    }
    r_[c] = extrinsicPriorResidual(e.T_calib, e.T, sigmas_, v.use_fej[c] ? &e.T_lin : nullptr, &J_[c]);
  }
}

void CalibrationPrior::addCost(const WindowVariables& v, bool trial, double& cost) const {
  for (int c = 0; c < v.window.numCameras(); ++c) {
    const ExtrinsicState& e = v.window.extrinsics[c];
    if (!e.variable || !e.calibration_prior) continue;
    const SE3& T = trial ? v.ext_trial[c] : e.T;
    cost += 0.5 * extrinsicPriorResidual(e.T_calib, T, sigmas_).squaredNorm();
  }
}

void CalibrationPrior::addToSystem(const WindowVariables& v, CameraSystem& sys) const {
  for (int c = 0; c < v.window.numCameras(); ++c) {
    const int b = v.ext_block[c];
    if (b < 0) continue;
    const Mat6& J = J_[c];
    sys.S.block<6, 6>(6 * b, 6 * b).noalias() += J.transpose() * J;
    sys.g.segment<6>(6 * b).noalias() += J.transpose() * r_[c];
    sys.D.segment<6>(6 * b) += J.colwise().squaredNorm().transpose();
  }
}

}  // namespace mcslam::backend
