#include "window_linearization.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "mcslam/backend/reprojection_residual.hpp"

namespace mcslam::backend {

namespace {
// Levenberg-Marquardt scales the damping by diag(H), clamped as Ceres does so that a variable
// without information still gets a (tiny) positive pivot.
constexpr double kMinDiagonal = 1e-6;
constexpr double kMaxDiagonal = 1e32;
double clampDiagonal(double v) { return std::clamp(v, kMinDiagonal, kMaxDiagonal); }

// Smallest over largest eigenvalue of a landmark's 3x3 information: parallax.
double conditioning(const Mat3& H) {
  Eigen::SelfAdjointEigenSolver<Mat3> es;
  es.computeDirect(H, Eigen::EigenvaluesOnly);
  const Vec3 ev = es.eigenvalues();
  return ev(2) > 0 ? ev(0) / ev(2) : 0.0;
}
}  // namespace

WindowLinearization::WindowLinearization(const WindowStorage& window, const SolverOptions& options)
    : options_(options) {
  const WindowCapacity& cap = window.capacity();
  num_cameras_ = window.numCameras();
  max_blocks_ = cap.max_keyframes + num_cameras_;
  ld_ = 6 * max_blocks_;
  ext_var_of_camera_.assign(num_cameras_, -1);
  for (int c = 0; c < num_cameras_; ++c) {
    if (window.extrinsics[c].variable) ext_var_of_camera_[c] = num_ext_vars_++;
  }
  pose_block_.assign(cap.max_keyframes, -1);
  ext_block_.assign(num_cameras_, -1);
  T_b_w_.resize(cap.max_keyframes);
  T_c_b_.resize(num_cameras_);
  T_c_b_jac_.resize(num_cameras_);
  use_fej_.assign(num_cameras_, false);
  landmarks_.resize(cap.max_landmarks);
  refs_.resize(cap.max_observations);
  lin_.resize(cap.max_observations);
  if (num_ext_vars_ > 0) je_.resize(cap.max_observations);
  prior_r_.resize(num_cameras_);
  prior_J_.resize(num_cameras_);
  S_.setZero(ld_, ld_);
  g_c_.setZero(ld_);
  D_c_.setZero(ld_);
  rhs_.setZero(ld_);
  dx_c_.setZero(ld_);
  d_current_.setZero(6 * num_ext_vars_);
  d_eval_.setZero(6 * num_ext_vars_);
  pattern_.assign(size_t(max_blocks_) * max_blocks_, 0);
  W_.resize(max_blocks_);
  touched_.resize(max_blocks_);
  touched_slot_.assign(max_blocks_, -1);
  kf_trial_.resize(cap.max_keyframes);
  held_slots_.resize(cap.max_keyframes);
  scale_J_.resize(cap.max_keyframes);
  ext_trial_.resize(num_cameras_);
  ext_d_trial_.resize(num_cameras_);
}

bool WindowLinearization::prepare(const WindowStorage& window, int fixed_oldest, bool hold_scale) {
  // Gauge: the oldest keyframes (and those the caller fixed) are held fixed. -2 marks fixed.
  const int K = static_cast<int>(window.keyframes.size());
  hold_scale_ = false;
  if (hold_scale) {
    // The unit from every keyframe between the oldest and the newest (the newest is the tracked one: its
    // distance is what the solve is to find); fewer than three keyframes: the two oldest hold it.
    int oldest = -1, newest = -1;
    for (int s = 0; s < K; ++s) {
      const KeyframeState& kf = window.keyframes[s];
      if (!kf.used) continue;
      if (oldest < 0 || kf.sequence < window.keyframes[oldest].sequence) oldest = s;
      if (newest < 0 || kf.sequence > window.keyframes[newest].sequence) newest = s;
    }
    num_held_ = 0;
    for (int s = 0; oldest >= 0 && s < K; ++s) {
      if (window.keyframes[s].used && s != oldest && s != newest) held_slots_[num_held_++] = s;
    }
    scale_anchor_ = oldest;
    const double d = num_held_ > 0 ? heldDistance(window, false) : 0;
    hold_scale_ = d > 0 && std::isfinite(d);
    if (hold_scale_) {
      log_held_distance_ = std::log(d);
      fixed_oldest = std::max(fixed_oldest, 1);
    } else {
      fixed_oldest = std::max(fixed_oldest, 2);
    }
  }
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
    use_fej_[c] = options_.first_estimate_jacobians && e.variable && e.in_prior;
    T_c_b_jac_[c] = use_fej_[c] ? e.T_lin.inverse() : T_c_b_[c];
  }
}

void WindowLinearization::linearize(const WindowStorage& window, const MarginalizationPrior& prior,
                                    bool select_landmarks) {
  updateTransforms(window);
  double cost = 0;
  landmarks_used_ = 0;
  residuals_used_ = 0;
  ReprojectionJacobians J;
  for (int i = 0; i < num_landmarks_; ++i) {
    LandmarkLin& L = landmarks_[i];
    if (!L.active) continue;
    const Vec3& p = window.landmarks[L.slot].p_w;
    Mat3 H = Mat3::Zero();
    double landmark_cost = 0;
    int valid = 0;
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
    if (select_landmarks && (valid < 2 || conditioning(H) < options_.min_landmark_conditioning)) {
      L.active = false;
      continue;
    }
    cost += landmark_cost;
    ++landmarks_used_;
    residuals_used_ += valid;
  }
  landmarks_skipped_ = window.num_landmarks - landmarks_used_;

  for (int c = 0; c < num_cameras_; ++c) {
    const ExtrinsicState& e = window.extrinsics[c];
    if (!e.variable) continue;
    if (!e.calibration_prior) {
      prior_r_[c].setZero();
      prior_J_[c].setZero();
      continue;
    }
    prior_r_[c] = extrinsicPriorResidual(e.T_calib, e.T, options_.extrinsic_prior, use_fej_[c] ? &e.T_lin : nullptr,
                                         &prior_J_[c]);
  }
  if (hold_scale_) {
    // d r / d rho_s = (t_s - t_a)^T R_s / (|t_s - t_a| D sigma): T_w_b exp(xi) moves t by R rho.
    const Vec3& anchor = window.keyframes[scale_anchor_].T_w_b.t;
    const double d = heldDistance(window, false);
    scale_r_ = scaleResidual(d);
    for (int i = 0; i < num_held_; ++i) {
      const KeyframeState& kf = window.keyframes[held_slots_[i]];
      const Vec3 v = kf.T_w_b.t - anchor;
      const double n = v.norm();
      scale_J_[i].setZero();
      if (n > 0) scale_J_[i].head<3>() = kf.T_w_b.R.transpose() * v / (n * d * kScaleSigma);
    }
  }
  cost_ = cost + priorCost(window, prior, false);
  d_current_ = d_eval_;
}

double WindowLinearization::heldDistance(const WindowStorage& window, bool trial) const {
  const Vec3& anchor = window.keyframes[scale_anchor_].T_w_b.t;  // held fixed: the same in a trial
  double d = 0;
  for (int i = 0; i < num_held_; ++i) {
    const int s = held_slots_[i];
    d += ((trial ? kf_trial_[s].t : window.keyframes[s].T_w_b.t) - anchor).norm();
  }
  return d;
}

double WindowLinearization::priorCost(const WindowStorage& window, const MarginalizationPrior& prior,
                                      bool trial) const {
  double cost = 0;
  if (hold_scale_) {
    const double r = scaleResidual(heldDistance(window, trial));
    cost += 0.5 * r * r;
  }
  for (int c = 0; c < num_cameras_; ++c) {
    const ExtrinsicState& e = window.extrinsics[c];
    if (!e.variable || !e.calibration_prior) continue;
    const SE3& T = trial ? ext_trial_[c] : e.T;
    cost += 0.5 * extrinsicPriorResidual(e.T_calib, T, options_.extrinsic_prior).squaredNorm();
  }
  if (!prior.empty) {
    // c + b^T d + 0.5 d^T H d, by loops: no temporaries.
    const int n = prior.dim();
    Eigen::VectorXd& d = d_eval_;
    for (int c = 0; c < num_cameras_; ++c) {
      const int v = ext_var_of_camera_[c];
      if (v >= 0) d.segment<6>(6 * v) = trial ? ext_d_trial_[c] : window.extrinsics[c].d;
    }
    double q = 0;
    for (int j = 0; j < n; ++j) {
      double hd = 0;
      for (int i = 0; i < n; ++i) hd += prior.H(i, j) * d(i);
      q += d(j) * (prior.b(j) + 0.5 * hd);
    }
    cost += prior.c + q;
  }
  return cost;
}

void WindowLinearization::buildReducedSystem(double mu, const MarginalizationPrior& prior) {
  const int n = 6 * num_blocks_;
  S_.topLeftCorner(n, n).setZero();
  g_c_.head(n).setZero();
  D_c_.head(n).setZero();
  rhs_.head(n).setZero();  // collects the landmarks' part of the reduced gradient
  for (int a = 0; a < num_blocks_; ++a) {
    std::fill_n(pattern_.begin() + size_t(a) * max_blocks_, max_blocks_, uint8_t(0));
    pattern_[size_t(a) * max_blocks_ + a] = 1;
  }

  // Calibration prior of each free extrinsic.
  for (int c = 0; c < num_cameras_; ++c) {
    const int b = ext_block_[c];
    if (b < 0) continue;
    const Mat6& J = prior_J_[c];
    S_.block<6, 6>(6 * b, 6 * b).noalias() += J.transpose() * J;
    g_c_.segment<6>(6 * b).noalias() += J.transpose() * prior_r_[c];
    D_c_.segment<6>(6 * b) += J.colwise().squaredNorm().transpose();
  }
  // Marginalization prior: gradient H d + b at the current d.
  if (!prior.empty) {
    for (int ca = 0; ca < num_cameras_; ++ca) {
      const int va = ext_var_of_camera_[ca];
      if (va < 0) continue;
      const int ba = ext_block_[ca];
      g_c_.segment<6>(6 * ba) += prior.b.segment<6>(6 * va);
      for (int cb = 0; cb < num_cameras_; ++cb) {
        const int vb = ext_var_of_camera_[cb];
        if (vb < 0) continue;
        const int bb = ext_block_[cb];
        const auto Hab = prior.H.block<6, 6>(6 * va, 6 * vb);
        g_c_.segment<6>(6 * ba).noalias() += Hab * d_current_.segment<6>(6 * vb);
        if (ba <= bb && !Hab.isZero(0.0)) {
          S_.block<6, 6>(6 * ba, 6 * bb) += Hab;
          pattern_[size_t(ba) * max_blocks_ + bb] = 1;
        }
      }
      D_c_.segment<6>(6 * ba) += prior.H.block<6, 6>(6 * va, 6 * va).diagonal();
    }
  }

  // The window's unit: one residual over every held keyframe's translation.
  for (int i = 0; hold_scale_ && i < num_held_; ++i) {
    const int a = pose_block_[held_slots_[i]];
    if (a < 0) continue;
    g_c_.segment<6>(6 * a) += scale_J_[i] * scale_r_;
    D_c_.segment<6>(6 * a) += scale_J_[i].cwiseAbs2();
    for (int j = 0; j < num_held_; ++j) {
      const int b = pose_block_[held_slots_[j]];
      if (b < a) continue;
      S_.block<6, 6>(6 * a, 6 * b).noalias() += scale_J_[i] * scale_J_[j].transpose();
      pattern_[size_t(a) * max_blocks_ + b] = 1;
    }
  }

  // Landmarks: accumulate H_cc directly and subtract W (H_ll + mu D_l)^-1 W^T per landmark.
  max_gradient_ = 0;
  for (int i = 0; i < num_landmarks_; ++i) {
    LandmarkLin& L = landmarks_[i];
    if (!L.active) continue;
    Mat3 H = Mat3::Zero();
    Vec3 g = Vec3::Zero();
    int num_touched = 0;
    auto touch = [&](int block) {
      int t = touched_slot_[block];
      if (t < 0) {
        t = num_touched++;
        touched_slot_[block] = t;
        touched_[t] = block;
        W_[t].setZero();
      }
      return t;
    };
    for (int k = L.begin; k < L.end; ++k) {
      const ObservationRef& ref = refs_[k];
      if (!ref.active) continue;
      const ObservationLin& o = lin_[k];
      H.noalias() += o.Jl * o.Jl.transpose();
      g.noalias() += o.Jl * o.r;
      const int pb = ref.pose_block, eb = ref.ext_block;
      if (pb >= 0) {
        W_[touch(pb)].noalias() += o.Jp * o.Jl.transpose();
        S_.block<6, 6>(6 * pb, 6 * pb).noalias() += o.Jp * o.Jp.transpose();
        g_c_.segment<6>(6 * pb).noalias() += o.Jp * o.r;
        D_c_.segment<6>(6 * pb) += o.Jp.rowwise().squaredNorm();
      }
      if (eb >= 0) {  // only when an extrinsic is refined: je_ is there
        const ExtrinsicJacobian& Je = je_[k];
        W_[touch(eb)].noalias() += Je * o.Jl.transpose();
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
    for (int ta = 0; ta < num_touched; ++ta) {
      const int a = touched_[ta];
      const Eigen::Matrix<double, 6, 3> V = W_[ta] * L.H_inv;
      rhs_.segment<6>(6 * a).noalias() += V * g;
      for (int tb = 0; tb < num_touched; ++tb) {
        const int b = touched_[tb];
        if (a > b) continue;
        S_.block<6, 6>(6 * a, 6 * b).noalias() -= V * W_[tb].transpose();
        pattern_[size_t(a) * max_blocks_ + b] = 1;
      }
    }
    for (int t = 0; t < num_touched; ++t) touched_slot_[touched_[t]] = -1;
  }

  for (int i = 0; i < n; ++i) {
    max_gradient_ = std::max(max_gradient_, std::abs(g_c_(i)));
    D_c_(i) = clampDiagonal(D_c_(i));
    S_(i, i) += mu * D_c_(i);
  }
  rhs_.head(n) -= g_c_.head(n);  // -(g_c - W H_ll^-1 g_l)
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

bool WindowLinearization::evaluateTrial(const WindowStorage& window, const MarginalizationPrior& prior,
                                        double& cost) {
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
      if (!reprojectionResidualInverse(window.rig().model(ob.camera), T_b_w_[ob.keyframe], T_c_b_[ob.camera],
                                       L.p_trial, ob.uv, ob.inv_sigma, r, nullptr)) {
        return false;
      }
      total += 0.5 * options_.loss.rho(r.squaredNorm());
    }
  }
  cost = total + priorCost(window, prior, true);
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
