#include "window_linearization.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "mcslam/backend/levenberg_marquardt.hpp"
#include "mcslam/backend/reprojection_residual.hpp"

namespace mcslam::backend {

namespace {
double clampDiagonal(double v) { return dampingDiagonal(v); }  // Marquardt's scaling

// Smallest over largest eigenvalue of a landmark's 3x3 information: parallax.
double conditioning(const Mat3& H) {
  Eigen::SelfAdjointEigenSolver<Mat3> es;
  es.computeDirect(H, Eigen::EigenvaluesOnly);
  const Vec3 ev = es.eigenvalues();
  return ev(2) > 0 ? ev(0) / ev(2) : 0.0;
}
}  // namespace

WindowLinearization::WindowLinearization(const WindowStorage& window, const SolverOptions& options)
    : options_(options),
      calibration_prior_(window.numCameras(), options.extrinsic_prior),
      scale_hold_(window.capacity().max_keyframes),
      schur_(window.capacity().max_keyframes + window.numCameras(),
             window.capacity().max_keyframes + window.numCameras()) {
  const WindowCapacity& cap = window.capacity();
  num_cameras_ = window.numCameras();
  max_blocks_ = cap.max_keyframes + num_cameras_;
  ld_ = 6 * max_blocks_;
  bool any_variable = false;
  for (int c = 0; c < num_cameras_; ++c) any_variable = any_variable || window.extrinsics[c].variable;
  pose_block_.assign(cap.max_keyframes, -1);
  ext_block_.assign(num_cameras_, -1);
  T_b_w_.resize(cap.max_keyframes);
  T_c_b_.resize(num_cameras_);
  T_c_b_jac_.resize(num_cameras_);
  use_fej_.assign(num_cameras_, 0);
  landmarks_.resize(cap.max_landmarks);
  refs_.resize(cap.max_observations);
  lin_.resize(cap.max_observations);
  if (any_variable) je_.resize(cap.max_observations);
  S_.setZero(ld_, ld_);
  g_c_.setZero(ld_);
  D_c_.setZero(ld_);
  rhs_.setZero(ld_);
  dx_c_.setZero(ld_);
  pattern_.assign(size_t(max_blocks_) * max_blocks_, 0);
  kf_trial_.resize(cap.max_keyframes);
  ext_trial_.resize(num_cameras_);
  ext_d_trial_.resize(num_cameras_);
}

bool WindowLinearization::prepare(const WindowStorage& window, int fixed_oldest, bool hold_scale) {
  // Gauge: the oldest keyframes (and those the caller fixed) are held fixed. -2 marks fixed.
  const int K = static_cast<int>(window.keyframes.size());
  scale_hold_.prepare(window, hold_scale);
  if (hold_scale) fixed_oldest = std::max(fixed_oldest, scale_hold_.active() ? 1 : 2);
  std::fill(pose_block_.begin(), pose_block_.end(), -1);
  for (int i = 0; i < fixed_oldest; ++i) {
    int oldest = -1;
    for (int s = 0; s < K; ++s) {
      const KeyframeState& kf = window.keyframes[s];
      if (kf.used && pose_block_[s] != -2 && (oldest < 0 || kf.sequence < window.keyframes[oldest].sequence)) {
        oldest = s;
      }
    }
    if (oldest >= 0) pose_block_[oldest] = -2;
  }
  num_blocks_ = 0;
  for (int s = 0; s < K; ++s) {
    const KeyframeState& kf = window.keyframes[s];
    const bool fixed = pose_block_[s] == -2 || kf.fixed_by_caller;
    pose_block_[s] = kf.used && !fixed ? num_blocks_++ : -1;
  }
  for (int c = 0; c < num_cameras_; ++c) ext_block_[c] = window.extrinsics[c].variable ? num_blocks_++ : -1;

  // Landmarks with at least two observations, their observations grouped together.
  num_landmarks_ = 0;
  num_refs_ = 0;
  for (int l = 0; l < static_cast<int>(window.landmarks.size()); ++l) {
    const LandmarkState& lm = window.landmarks[l];
    if (!lm.used || lm.num_observations < 2) continue;
    LandmarkLin& L = landmarks_[num_landmarks_++];
    L.slot = l;
    L.begin = num_refs_;
    L.active = true;
    L.dx.setZero();
    for (int o = lm.first_observation; o >= 0; o = window.observations[o].next) {
      const ObservationState& ob = window.observations[o];
      refs_[num_refs_++] = {o, pose_block_[ob.keyframe], ext_block_[ob.camera], true};
    }
    L.end = num_refs_;
  }
  return num_landmarks_ > 0;
}

void WindowLinearization::updateTransforms(const WindowStorage& window) {
  for (size_t s = 0; s < window.keyframes.size(); ++s) {
    if (window.keyframes[s].used) T_b_w_[s] = window.keyframes[s].T_w_b.inverse();
  }
  for (int c = 0; c < num_cameras_; ++c) {
    const ExtrinsicState& e = window.extrinsics[c];
    T_c_b_[c] = e.T.inverse();
    use_fej_[c] = options_.first_estimate_jacobians && e.variable && e.in_prior ? 1 : 0;
    T_c_b_jac_[c] = use_fej_[c] ? e.T_lin.inverse() : T_c_b_[c];
  }
}

WindowVariables WindowLinearization::variables(const WindowStorage& window) const {
  return {window, pose_block_, ext_block_, use_fej_, kf_trial_, ext_trial_, ext_d_trial_};
}

double WindowLinearization::linearizeLandmark(const WindowStorage& window, LandmarkLin& L, bool select_landmarks,
                                              int& valid, Mat3& H) {
  const Vec3& p = window.landmarks[L.slot].p_w;
  ReprojectionJacobians J;
  H.setZero();
  double landmark_cost = 0;
  valid = 0;
  for (int k = L.begin; k < L.end; ++k) {
    ObservationRef& ref = refs_[k];
    if (!ref.active) continue;
    const ObservationState& ob = window.observations[ref.slot];
    const CameraModel& model = window.rig().model(ob.camera);
    const SE3& T_b_w = T_b_w_[ob.keyframe];
    Vec2 r;
    bool ok;
    if (use_fej_[ob.camera]) {
      // Residual at the current extrinsic, Jacobians at its first estimate.
      ok = reprojectionResidualInverse(model, T_b_w, T_c_b_[ob.camera], p, ob.uv, ob.inv_sigma, r, nullptr);
      Vec2 r_lin;
      if (ok && !reprojectionResidualInverse(model, T_b_w, T_c_b_jac_[ob.camera], p, ob.uv, ob.inv_sigma, r_lin, &J)) {
        reprojectionResidualInverse(model, T_b_w, T_c_b_[ob.camera], p, ob.uv, ob.inv_sigma, r_lin, &J);
      }
    } else {
      ok = reprojectionResidualInverse(model, T_b_w, T_c_b_[ob.camera], p, ob.uv, ob.inv_sigma, r, &J);
    }
    ObservationLin& o = lin_[k];
    if (!ok) {
      // Cannot happen after an accepted trial (it projected there); on selection, drop it.
      if (select_landmarks) ref.active = false;
      o.r.setZero();
      o.Jp.setZero();
      if (!je_.empty()) je_[k].setZero();
      o.Jl.setZero();
      continue;
    }
    double rho, weight;
    options_.loss.evaluate(r.squaredNorm(), rho, weight);
    landmark_cost += 0.5 * rho;
    const double sw = std::sqrt(weight);
    o.r = sw * r;
    o.Jp = sw * J.pose.transpose();
    if (!je_.empty()) je_[k] = sw * J.extrinsic.transpose();
    o.Jl = sw * J.point.transpose();
    H.noalias() += o.Jl * o.Jl.transpose();
    ++valid;
  }
  return landmark_cost;
}

void WindowLinearization::linearize(const WindowStorage& window, MarginalizationPrior& prior, bool select_landmarks) {
  updateTransforms(window);
  double cost = 0;
  landmarks_used_ = 0;
  residuals_used_ = 0;
  for (int i = 0; i < num_landmarks_; ++i) {
    LandmarkLin& L = landmarks_[i];
    if (!L.active) continue;
    Mat3 H;
    int valid = 0;
    const double landmark_cost = linearizeLandmark(window, L, select_landmarks, valid, H);
    if (select_landmarks && (valid < 2 || conditioning(H) < options_.min_landmark_conditioning)) {
      L.active = false;
      continue;
    }
    cost += landmark_cost;
    ++landmarks_used_;
    residuals_used_ += valid;
  }
  landmarks_skipped_ = window.num_landmarks - landmarks_used_;
  const WindowVariables v = variables(window);
  for (WindowTerm* term : terms(prior)) term->linearize(v);
  cost_ = cost + termsCost(window, prior, false);
}

double WindowLinearization::termsCost(const WindowStorage& window, const MarginalizationPrior& prior,
                                      bool trial) const {
  const WindowVariables v = variables(window);
  double cost = 0;
  for (const WindowTerm* term : terms(prior)) term->addCost(v, trial, cost);
  return cost;
}

void WindowLinearization::buildReducedSystem(const WindowStorage& window, double mu,
                                             const MarginalizationPrior& prior) {
  const int n = 6 * num_blocks_;
  S_.topLeftCorner(n, n).setZero();
  g_c_.head(n).setZero();
  D_c_.head(n).setZero();
  rhs_.head(n).setZero();  // collects the landmarks' part of the reduced gradient, negated
  for (int a = 0; a < num_blocks_; ++a) {
    std::fill_n(pattern_.begin() + size_t(a) * max_blocks_, max_blocks_, uint8_t(0));
    pattern_[size_t(a) * max_blocks_ + a] = 1;
  }
  CameraSystem system{S_, g_c_, D_c_, pattern_.data(), max_blocks_};
  const WindowVariables v = variables(window);
  for (const WindowTerm* term : terms(prior)) term->addToSystem(v, system);

  // Landmarks: accumulate H_cc directly and subtract W (H_ll + mu D_l)^-1 W^T per landmark.
  max_gradient_ = 0;
  for (int i = 0; i < num_landmarks_; ++i) {
    if (landmarks_[i].active) eliminateLandmark(landmarks_[i], mu);
  }

  for (int i = 0; i < n; ++i) {
    max_gradient_ = std::max(max_gradient_, std::abs(g_c_(i)));
    D_c_(i) = clampDiagonal(D_c_(i));
    S_(i, i) += mu * D_c_(i);
  }
  rhs_.head(n) = -rhs_.head(n) - g_c_.head(n);  // -(g_c - W H_ll^-1 g_l): rhs_ held -W H_ll^-1 g_l
}

void WindowLinearization::eliminateLandmark(LandmarkLin& L, double mu) {
  Mat3 H = Mat3::Zero();
  Vec3 g = Vec3::Zero();
  schur_.beginPoint();
  for (int k = L.begin; k < L.end; ++k) {
    const ObservationRef& ref = refs_[k];
    if (!ref.active) continue;
    const ObservationLin& o = lin_[k];
    H.noalias() += o.Jl * o.Jl.transpose();
    g.noalias() += o.Jl * o.r;
    const int pb = ref.pose_block, eb = ref.ext_block;
    if (pb >= 0) {
      schur_.coupling(pb).noalias() += o.Jp * o.Jl.transpose();
      S_.block<6, 6>(6 * pb, 6 * pb).noalias() += o.Jp * o.Jp.transpose();
      g_c_.segment<6>(6 * pb).noalias() += o.Jp * o.r;
      D_c_.segment<6>(6 * pb) += o.Jp.rowwise().squaredNorm();
    }
    if (eb >= 0) {  // only when an extrinsic is refined: je_ is there
      const ExtrinsicJacobian& Je = je_[k];
      schur_.coupling(eb).noalias() += Je * o.Jl.transpose();
      S_.block<6, 6>(6 * eb, 6 * eb).noalias() += Je * Je.transpose();
      g_c_.segment<6>(6 * eb).noalias() += Je * o.r;
      D_c_.segment<6>(6 * eb) += Je.rowwise().squaredNorm();
    }
    if (pb >= 0 && eb >= 0) {  // pose blocks come before extrinsic blocks
      S_.block<6, 6>(6 * pb, 6 * eb).noalias() += o.Jp * je_[k].transpose();
      pattern_[size_t(pb) * max_blocks_ + eb] = 1;
    }
  }
  L.g = g;
  max_gradient_ = std::max(max_gradient_, g.cwiseAbs().maxCoeff());
  L.D = H.diagonal().unaryExpr([](double v) { return clampDiagonal(v); });
  Mat3 Hd = H;
  Hd.diagonal() += mu * L.D;
  L.H_inv = Hd.inverse();
  schur_.eliminate(L.H_inv, g, S_, rhs_, pattern_.data(), max_blocks_);
}

void WindowLinearization::backSubstitute() {
  for (int i = 0; i < num_landmarks_; ++i) {
    LandmarkLin& L = landmarks_[i];
    if (!L.active) continue;
    Vec3 t = L.g;
    for (int k = L.begin; k < L.end; ++k) {
      const ObservationRef& ref = refs_[k];
      if (!ref.active) continue;
      const ObservationLin& o = lin_[k];
      Vec2 v = Vec2::Zero();
      if (ref.pose_block >= 0) v.noalias() += o.Jp.transpose() * dx_c_.segment<6>(6 * ref.pose_block);
      if (ref.ext_block >= 0) v.noalias() += je_[k].transpose() * dx_c_.segment<6>(6 * ref.ext_block);
      t.noalias() += o.Jl * v;
    }
    L.dx.noalias() = -L.H_inv * t;
  }
}

double WindowLinearization::modelCostDecrease(double mu) const {
  // With (H + mu D) dx = -g: -(g^T dx + 0.5 dx^T H dx) = -0.5 g^T dx + 0.5 mu dx^T D dx.
  double dec = 0;
  const int n = 6 * num_blocks_;
  for (int i = 0; i < n; ++i) dec += -0.5 * g_c_(i) * dx_c_(i) + 0.5 * mu * D_c_(i) * dx_c_(i) * dx_c_(i);
  for (int i = 0; i < num_landmarks_; ++i) {
    const LandmarkLin& L = landmarks_[i];
    if (!L.active) continue;
    dec += -0.5 * L.g.dot(L.dx) + 0.5 * mu * (L.D.array() * L.dx.array().square()).sum();
  }
  return dec;
}

double WindowLinearization::stepSquaredNorm() const {
  double s = dx_c_.head(6 * num_blocks_).squaredNorm();
  for (int i = 0; i < num_landmarks_; ++i) {
    if (landmarks_[i].active) s += landmarks_[i].dx.squaredNorm();
  }
  return s;
}

double WindowLinearization::stateSquaredNorm(const WindowStorage& window) const {
  double s = 0;
  for (const KeyframeState& kf : window.keyframes) {
    if (kf.used) s += kf.T_w_b.t.squaredNorm() + 1.0;  // + unit quaternion, as Ceres counts it
  }
  for (int i = 0; i < num_landmarks_; ++i) {
    if (landmarks_[i].active) s += window.landmarks[landmarks_[i].slot].p_w.squaredNorm();
  }
  return s;
}

bool WindowLinearization::evaluateTrial(const WindowStorage& window, const MarginalizationPrior& prior, double& cost) {
  for (size_t s = 0; s < window.keyframes.size(); ++s) {
    const KeyframeState& kf = window.keyframes[s];
    if (!kf.used) continue;
    kf_trial_[s] = pose_block_[s] >= 0 ? kf.T_w_b * SE3::exp(dx_c_.segment<6>(6 * pose_block_[s])) : kf.T_w_b;
    T_b_w_[s] = kf_trial_[s].inverse();
  }
  for (int c = 0; c < num_cameras_; ++c) {
    const ExtrinsicState& e = window.extrinsics[c];
    if (ext_block_[c] >= 0) {
      ext_d_trial_[c] = e.d + dx_c_.segment<6>(6 * ext_block_[c]);
      ext_trial_[c] = e.T_lin * SE3::exp(ext_d_trial_[c]);
    } else {
      ext_d_trial_[c] = e.d;
      ext_trial_[c] = e.T;
    }
    T_c_b_[c] = ext_trial_[c].inverse();
  }
  double total = 0;
  for (int i = 0; i < num_landmarks_; ++i) {
    LandmarkLin& L = landmarks_[i];
    if (!L.active) continue;
    L.p_trial = window.landmarks[L.slot].p_w + L.dx;
    for (int k = L.begin; k < L.end; ++k) {
      const ObservationRef& ref = refs_[k];
      if (!ref.active) continue;
      const ObservationState& ob = window.observations[ref.slot];
      Vec2 r;
      if (!reprojectionResidualInverse(window.rig().model(ob.camera), T_b_w_[ob.keyframe], T_c_b_[ob.camera], L.p_trial,
                                       ob.uv, ob.inv_sigma, r, nullptr)) {
        return false;
      }
      total += 0.5 * options_.loss.rho(r.squaredNorm());
    }
  }
  cost = total + termsCost(window, prior, true);
  return std::isfinite(cost);
}

void WindowLinearization::commitTrial(WindowStorage& window) const {
  for (size_t s = 0; s < window.keyframes.size(); ++s) {
    KeyframeState& kf = window.keyframes[s];
    if (!kf.used || pose_block_[s] < 0) continue;
    kf.T_w_b = kf_trial_[s];
    kf.T_w_b.normalize();
  }
  for (int c = 0; c < num_cameras_; ++c) {
    ExtrinsicState& e = window.extrinsics[c];
    if (ext_block_[c] < 0) continue;
    e.T = ext_trial_[c];
    e.T.normalize();
    if (e.in_prior) {
      e.d = ext_d_trial_[c];
    } else {  // not linked to the prior: rebase, so the next step is a plain right perturbation
      e.T_lin = e.T;
      e.d.setZero();
    }
  }
  for (int i = 0; i < num_landmarks_; ++i) {
    const LandmarkLin& L = landmarks_[i];
    if (L.active) window.landmarks[L.slot].p_w = L.p_trial;
  }
}

double WindowLinearization::maxGradient() const { return max_gradient_; }

}  // namespace mcslam::backend
