#include "window_scale_hold.hpp"

namespace mcslam::backend {

void WindowScaleHold::prepare(const WindowStorage& window, bool hold) {
  active_ = false;
  if (!hold) return;
  const int K = static_cast<int>(window.keyframes.size());
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
  anchor_ = oldest;
  const double d = num_held_ > 0 ? heldDistance(window, nullptr) : 0;
  active_ = d > 0 && std::isfinite(d);
  if (active_) log_reference_ = std::log(d);
}

double WindowScaleHold::heldDistance(const WindowStorage& window, const SE3* kf_trial) const {
  const Vec3& anchor = window.keyframes[anchor_].T_w_b.t;  // held fixed: the same in a trial
  double d = 0;
  for (int i = 0; i < num_held_; ++i) {
    const int s = held_slots_[i];
    d += ((kf_trial ? kf_trial[s].t : window.keyframes[s].T_w_b.t) - anchor).norm();
  }
  return d;
}

void WindowScaleHold::linearize(const WindowVariables& v) {
  if (!active_) return;
  // d r / d rho_s = (t_s - t_a)^T R_s / (|t_s - t_a| D sigma): T_w_b exp(xi) moves t by R rho.
  const Vec3& anchor = v.window.keyframes[anchor_].T_w_b.t;
  const double d = heldDistance(v.window, nullptr);
  r_ = residual(d);
  for (int i = 0; i < num_held_; ++i) {
    const KeyframeState& kf = v.window.keyframes[held_slots_[i]];
    const Vec3 t = kf.T_w_b.t - anchor;
    const double n = t.norm();
    J_[i].setZero();
    if (n > 0) J_[i].head<3>() = kf.T_w_b.R.transpose() * t / (n * d * kSigma);
  }
}

void WindowScaleHold::addCost(const WindowVariables& v, bool trial, double& cost) const {
  if (!active_) return;
  const double r = residual(heldDistance(v.window, trial ? v.kf_trial.data() : nullptr));
  cost += 0.5 * r * r;
}

void WindowScaleHold::addToSystem(const WindowVariables& v, CameraSystem& sys) const {
  for (int i = 0; active_ && i < num_held_; ++i) {
    const int a = v.pose_block[held_slots_[i]];
    if (a < 0) continue;
    sys.g.segment<6>(6 * a) += J_[i] * r_;
    sys.D.segment<6>(6 * a) += J_[i].cwiseAbs2();
    for (int j = 0; j < num_held_; ++j) {
      const int b = v.pose_block[held_slots_[j]];
      if (b < a) continue;
      sys.S.block<6, 6>(6 * a, 6 * b).noalias() += J_[i] * J_[j].transpose();
      sys.mark(a, b);
    }
  }
}

}  // namespace mcslam::backend
