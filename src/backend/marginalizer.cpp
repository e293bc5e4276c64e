#include "marginalizer.hpp"

#include <algorithm>
#include <cmath>

#include "mcslam/backend/reprojection_residual.hpp"

namespace mcslam::backend {

namespace {
// Eigenvalues below this fraction of the largest are treated as zero (null space).
constexpr double kRelativeRankTolerance = 1e-10;

double conditioning(const Mat3& H) {
  Eigen::SelfAdjointEigenSolver<Mat3> es;
  es.computeDirect(H, Eigen::EigenvaluesOnly);
  return es.eigenvalues()(2) > 0 ? es.eigenvalues()(0) / es.eigenvalues()(2) : 0.0;
}

// Pseudo-inverse of a symmetric PSD 6x6 block, Jacobi-scaled so translation and rotation
// magnitudes do not decide the rank; eigenvalues below `floor` (absolute, after scaling back
// to the original magnitude `scale`) are dropped.
Mat6 pseudoInverse(const Mat6& H, double scale) {
  Vec6 s;
  for (int i = 0; i < 6; ++i) s(i) = H(i, i) > 0 ? 1.0 / std::sqrt(H(i, i)) : 0.0;
  const Mat6 A = s.asDiagonal() * H * s.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Mat6> es(A);
  Vec6 inv = Vec6::Zero();
  // A's eigenvalues are relative to H's diagonal; also require the diagonal itself to be
  // significant against the magnitude before elimination (else it is rounding noise).
  const double max_diag = H.diagonal().maxCoeff();
  if (!(max_diag > kRelativeRankTolerance * scale)) return Mat6::Zero();
  for (int i = 0; i < 6; ++i) {
    if (es.eigenvalues()(i) > kRelativeRankTolerance * es.eigenvalues()(5)) inv(i) = 1.0 / es.eigenvalues()(i);
  }
  return s.asDiagonal() * es.eigenvectors() * inv.asDiagonal() * es.eigenvectors().transpose() * s.asDiagonal();
}
}  // namespace

Marginalizer::Marginalizer(const WindowStorage& window, const SolverOptions& options)
    : options_(options), schur_(window.numCameras() + 1, window.numCameras() + 1) {
  const int C = window.numCameras();
  ext_var_of_camera_.assign(C, -1);
  for (int c = 0; c < C; ++c) {
    if (window.extrinsics[c].variable) ext_var_of_camera_[c] = num_ext_vars_++;
  }
  const int n = 6 * num_ext_vars_;
  obs_.resize(C);
  H_.setZero(6 + n, 6 + n);
  g_.setZero(6 + n);
  K_.setZero(n, 6);
  Hn_.setZero(n, n);
  gn_.setZero(n);
}

bool Marginalizer::isExclusiveTo(const WindowStorage& window, int landmark, int keyframe) const {
  const LandmarkState& lm = window.landmarks[landmark];
  if (lm.num_observations == 0) return false;
  for (int o = lm.first_observation; o >= 0; o = window.observations[o].next) {
    if (window.observations[o].keyframe != keyframe) return false;
  }
  return true;
}

Status Marginalizer::marginalizeOldest(WindowStorage& window, MarginalizationPrior& prior,
                                       std::vector<int64_t>& removed) {
  removed.clear();
  const int k0 = window.oldestKeyframe();
  if (k0 < 0) return Status::EmptyWindow;
  if (num_ext_vars_ > 0) {
    accumulateExclusiveLandmarks(window, k0);
    foldIntoPrior(window, prior);
  }
  for (int l = 0; l < static_cast<int>(window.landmarks.size()); ++l) {
    if (!window.landmarks[l].used || !isExclusiveTo(window, l, k0)) continue;
    removed.push_back(window.landmarks[l].id);
    window.removeLandmarkSlot(l);
  }
  // The oldest keyframe's observations of landmarks that stay are dropped.
  for (int o = 0; o < static_cast<int>(window.observations.size()); ++o) {
    if (window.observations[o].used && window.observations[o].keyframe == k0) window.removeObservationSlot(o);
  }
  window.removeKeyframeSlot(k0);
  return Status::Ok;
}

void Marginalizer::accumulateExclusiveLandmarks(const WindowStorage& window, int k0) {
  H_.setZero();
  g_.setZero();
  c_ = 0;
  pose_scale_ = 0;
  const SE3 T_b_w = window.keyframes[k0].T_w_b.inverse();
  for (int l = 0; l < static_cast<int>(window.landmarks.size()); ++l) {
    const LandmarkState& lm = window.landmarks[l];
    if (!lm.used || lm.num_observations < 2 || !isExclusiveTo(window, l, k0)) continue;

    // Linearize at the current state; Jacobians of prior-linked extrinsics at their first estimate.
    int n = 0;
    Mat3 Hll = Mat3::Zero();
    Vec3 gl = Vec3::Zero();
    for (int o = lm.first_observation; o >= 0; o = window.observations[o].next) {
      const ObservationState& ob = window.observations[o];
      const ExtrinsicState& e = window.extrinsics[ob.camera];
      const CameraModel& model = window.rig().model(ob.camera);
      const bool fej = options_.first_estimate_jacobians && e.variable && e.in_prior;
      Vec2 r, r_lin;
      ReprojectionJacobians J;
      if (!reprojectionResidualInverse(model, T_b_w, e.T.inverse(), lm.p_w, ob.uv, ob.inv_sigma, r, &J)) continue;
      if (fej) reprojectionResidualInverse(model, T_b_w, e.T_lin.inverse(), lm.p_w, ob.uv, ob.inv_sigma, r_lin, &J);
      double rho, weight;
      options_.loss.evaluate(r.squaredNorm(), rho, weight);
      const double sw = std::sqrt(weight);
      ObservationLin& x = obs_[n++];
      x.r = sw * r;
      x.Jp = sw * J.pose;
      x.Je = sw * J.extrinsic;
      x.Jl = sw * J.point;
      x.ext_var = ext_var_of_camera_[ob.camera];
      Hll.noalias() += x.Jl.transpose() * x.Jl;
      gl.noalias() += x.Jl.transpose() * x.r;
    }
    // Two views of one keyframe without parallax tell nothing after elimination: skip.
    if (n < 2 || conditioning(Hll) < options_.min_landmark_conditioning) continue;

    // Direct terms, blocks [0] pose and [1 + v] extrinsic v (rows 6 + 6v); their couplings H_{t,l}.
    schur_.beginPoint();
    for (int i = 0; i < n; ++i) {
      const ObservationLin& x = obs_[i];
      c_ += 0.5 * x.r.squaredNorm();
      H_.topLeftCorner<6, 6>().noalias() += x.Jp.transpose() * x.Jp;
      g_.head<6>().noalias() += x.Jp.transpose() * x.r;
      schur_.coupling(0).noalias() += x.Jp.transpose() * x.Jl;
      if (x.ext_var < 0) continue;
      const int e = 6 + 6 * x.ext_var;
      H_.block<6, 6>(e, e).noalias() += x.Je.transpose() * x.Je;
      H_.block<6, 6>(0, e).noalias() += x.Jp.transpose() * x.Je;
      H_.block<6, 6>(e, 0).noalias() += x.Je.transpose() * x.Jp;
      g_.segment<6>(e).noalias() += x.Je.transpose() * x.r;
      schur_.coupling(1 + x.ext_var).noalias() += x.Je.transpose() * x.Jl;
    }
    pose_scale_ = std::max(pose_scale_, H_.topLeftCorner<6, 6>().diagonal().maxCoeff());

    // Eliminate the landmark: H -= W H_ll^-1 W^T, g -= W H_ll^-1 g_l (H_ll is well conditioned here).
    const Mat3 Hinv = Hll.llt().solve(Mat3::Identity());
    c_ -= 0.5 * gl.dot(Hinv * gl);
    schur_.eliminate(Hinv, gl, H_, g_);
  }
}

void Marginalizer::foldIntoPrior(WindowStorage& window, MarginalizationPrior& prior) {
  const int n = 6 * num_ext_vars_;
  // Eliminate the pose. Its information left after the landmarks is zero up to rounding (moving
  // the keyframe with its own landmarks changes no residual), so the pseudo-inverse has to tell
  // rounding noise from information: ranks are judged against the pre-elimination magnitude.
  const Mat6 P = pseudoInverse(H_.topLeftCorner<6, 6>(), pose_scale_);
  K_.noalias() = H_.bottomLeftCorner(n, 6) * P;
  Hn_ = H_.bottomRightCorner(n, n);
  Hn_.noalias() -= K_ * H_.topRightCorner(6, n);
  gn_ = g_.tail(n);
  gn_.noalias() -= K_ * g_.head<6>();
  double c = c_ - 0.5 * g_.head<6>().dot(P * g_.head<6>());

  prior.absorb(Hn_, gn_, c, window);
}

}  // namespace mcslam::backend
