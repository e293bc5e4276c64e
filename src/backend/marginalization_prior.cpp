#include "marginalization_prior.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>

#include "symmetric_eigen.hpp"

namespace mcslam::backend {

namespace {
// Eigenvalues below this fraction of the largest are treated as zero (null space).
constexpr double kRelativeRankTolerance = 1e-10;
}  // namespace

MarginalizationPrior::MarginalizationPrior(const WindowStorage& window) {
  int n = 0;
  ext_var_of_camera_.assign(window.numCameras(), -1);
  for (int cam = 0; cam < window.numCameras(); ++cam) {
    if (window.extrinsics[cam].variable) ext_var_of_camera_[cam] = n++;
  }
  H.setZero(6 * n, 6 * n);
  b.setZero(6 * n);
  d_current_.setZero(6 * n);
  d_eval_.setZero(6 * n);
  d_.setZero(6 * n);
  tmp_.setZero(6 * n);
  scratch_.setZero(6 * n, 6 * n);
  V_.setZero(6 * n, 6 * n);
}

void MarginalizationPrior::clear() {
  H.setZero();
  b.setZero();
  c = 0;
  empty = true;
  d_current_.setZero();
  d_eval_.setZero();
}

void MarginalizationPrior::stackCurrent(const WindowStorage& window, Eigen::VectorXd& d) const {
  for (int cam = 0; cam < static_cast<int>(ext_var_of_camera_.size()); ++cam) {
    const int v = ext_var_of_camera_[cam];
    if (v >= 0) d.segment<6>(6 * v) = window.extrinsics[cam].d;
  }
}

void MarginalizationPrior::linearize(const WindowVariables& v) {
  if (!empty) stackCurrent(v.window, d_current_);
}

void MarginalizationPrior::addCost(const WindowVariables& v, bool trial, double& cost) const {
  if (empty) return;
  // c + b^T d + 0.5 d^T H d, by loops: no temporaries.
  const int n = dim();
  Eigen::VectorXd& d = d_eval_;
  for (int cam = 0; cam < static_cast<int>(ext_var_of_camera_.size()); ++cam) {
    const int var = ext_var_of_camera_[cam];
    if (var >= 0) d.segment<6>(6 * var) = trial ? v.ext_d_trial[cam] : v.window.extrinsics[cam].d;
  }
  double q = 0;
  for (int j = 0; j < n; ++j) {
    double hd = 0;
    for (int i = 0; i < n; ++i) hd += H(i, j) * d(i);
    q += d(j) * (b(j) + 0.5 * hd);
  }
  cost += c + q;
}

void MarginalizationPrior::addToSystem(const WindowVariables& v, CameraSystem& sys) const {
  if (empty) return;
  // Gradient H d + b at the current d.
  const int C = static_cast<int>(ext_var_of_camera_.size());
  for (int ca = 0; ca < C; ++ca) {
    const int va = ext_var_of_camera_[ca];
    if (va < 0) continue;
    const int ba = v.ext_block[ca];
    sys.g.segment<6>(6 * ba) += b.segment<6>(6 * va);
    for (int cb = 0; cb < C; ++cb) {
      const int vb = ext_var_of_camera_[cb];
      if (vb < 0) continue;
      const int bb = v.ext_block[cb];
      const auto Hab = H.block<6, 6>(6 * va, 6 * vb);
      sys.g.segment<6>(6 * ba).noalias() += Hab * d_current_.segment<6>(6 * vb);
      if (ba <= bb && !Hab.isZero(0.0)) {
        sys.S.block<6, 6>(6 * ba, 6 * bb) += Hab;
        sys.mark(ba, bb);
      }
    }
    sys.D.segment<6>(6 * ba) += H.block<6, 6>(6 * va, 6 * va).diagonal();
  }
}

void MarginalizationPrior::absorb(const Eigen::MatrixXd& Hn, const Eigen::VectorXd& gn, double cn,
                                  WindowStorage& window) {
  const int n = dim();
  // Re-express around the fixed linearization point: the new terms were linearized at the
  // current d, E(d') = c + gn^T (d' - d) + 0.5 (d' - d)^T Hn (d' - d).
  stackCurrent(window, d_);
  tmp_.noalias() = Hn * d_;
  c += cn - gn.dot(d_) + 0.5 * d_.dot(tmp_);
  b += gn - tmp_;
  H += Hn;

  // Symmetric PSD: symmetrize, clamp eigenvalues that rounding pushed below zero, and remove
  // the gradient's component in the null space (it would pull the extrinsics without bound).
  scratch_ = H.transpose();
  H += scratch_;
  H *= 0.5;
  jacobiEigen(H, V_);  // H now holds the eigenvalues on its diagonal
  double top = 0;
  for (int i = 0; i < n; ++i) top = std::max(top, H(i, i));
  const double floor = kRelativeRankTolerance * top;
  tmp_.noalias() = V_.transpose() * b;
  scratch_ = V_;
  for (int i = 0; i < n; ++i) {
    const double lambda = H(i, i);
    if (!(lambda > floor)) tmp_(i) = 0;
    scratch_.col(i) *= lambda > floor ? lambda : 0.0;
  }
  b.noalias() = V_ * tmp_;
  H.noalias() = scratch_ * V_.transpose();
  H.triangularView<Eigen::StrictlyLower>() = H.transpose();  // exactly symmetric
  empty = false;

  // Extrinsics that received information keep their linearization point from now on.
  for (int cam = 0; cam < static_cast<int>(ext_var_of_camera_.size()); ++cam) {
    const int v = ext_var_of_camera_[cam];
    if (v >= 0 && Hn.block<6, 6>(6 * v, 6 * v).trace() > 0) window.extrinsics[cam].in_prior = true;
  }
}

void MarginalizationPrior::forgetExtrinsic(int camera, WindowStorage& window) {
  const int k = 6 * ext_var_of_camera_[camera];
  // Pseudo-inverse of the camera's block (it may hold information in some directions only).
  const Eigen::SelfAdjointEigenSolver<Mat6> eig(H.block<6, 6>(k, k));
  const double floor = 1e-12 * std::max(1.0, eig.eigenvalues().cwiseAbs().maxCoeff());
  Vec6 inv = Vec6::Zero();
  for (int i = 0; i < 6; ++i) inv(i) = eig.eigenvalues()(i) > floor ? 1.0 / eig.eigenvalues()(i) : 0.0;
  const Mat6 P = eig.eigenvectors() * inv.asDiagonal() * eig.eigenvectors().transpose();
  const Eigen::MatrixXd Hc = H.middleCols<6>(k);  // column block of the camera
  const Vec6 bc = b.segment<6>(k);
  c -= 0.5 * bc.dot(P * bc);
  b.noalias() -= Hc * (P * bc);
  H.noalias() -= Hc * P * Hc.transpose();
  H.middleCols<6>(k).setZero();
  H.middleRows<6>(k).setZero();
  b.segment<6>(k).setZero();
  window.extrinsics[camera].in_prior = false;
}

}  // namespace mcslam::backend
