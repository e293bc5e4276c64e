#include "mcslam/odometry/scale_estimator.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <bit>
#include <limits>

#include "mcslam/backend/levenberg_marquardt.hpp"
#include "mcslam/backend/reprojection_residual.hpp"

namespace mcslam {

namespace {
// A ray that no longer projects costs as much as a residual of this many sigmas: large, but bounded, so
// that the cost stays continuous enough to search.
constexpr double kMissingSigmas = 10.0;
constexpr int kRefineSteps = 6;
constexpr double kInitialRadius = 1e6;
constexpr int kMaxRefusals = 10;
// The profile's spacing in s, and the steps that re-fit the window at each factor (from its neighbour's fit): the
// profile only chooses the basin, the free refinement then finds the minimum in it.
constexpr double kProfileRatio = 1.4;
constexpr int kProfileSteps = 2;
}  // namespace

ScaleEstimator::ScaleEstimator(const Rig& rig, int max_landmarks, int max_observations, int max_keyframes,
                               float octave_scale_factor, int levels)
    : rig_(rig), schur_(kMaxKeyframes, kMaxLandmarkObservations) {
  kf_slot_of_.resize(max_keyframes);
  kf_order_.resize(max_keyframes);
  for (int o = 0; o < std::max(levels, 1); ++o) octave_sigma_.push_back(std::pow(octave_scale_factor, o));
  kf_T_.resize(kMaxKeyframes);
  kf_before_.resize(kMaxKeyframes);
  kf_start_.resize(kMaxKeyframes);
  kf_best_.resize(kMaxKeyframes);
  T_c_b_.resize(rig.size());
  lm_p_.resize(max_landmarks);
  eligible_.resize(max_landmarks);
  lm_start_.resize(max_landmarks);
  lm_best_.resize(max_landmarks);
  lm_first_.resize(static_cast<std::size_t>(max_landmarks) + 1);
  obs_.resize(max_observations);
}

double ScaleEstimator::landmarkCost(int l, Vec3& p) {
  const int begin = lm_first_[l], end = lm_first_[l + 1];
  const double missing = loss_.rho(kMissingSigmas * kMissingSigmas);
  auto cameraPoint = [&](const Obs& o) {
    const SE3& T_b_c = rig_.T_b_c(o.cam);
    const SE3& T = kf_T_[o.kf];
    return Vec3(T_b_c.R.transpose() * (T.R.transpose() * (p - T.t) - T_b_c.t));
  };
  for (int it = 0; it < 2; ++it) {
    Mat3 H = Mat3::Zero();
    Vec3 g = Vec3::Zero();
    for (int i = begin; i < end; ++i) {
      const Obs& o = obs_[i];
      Vec2 uv;
      Mat23 J;
      if (!rig_.model(o.cam).project(cameraPoint(o), uv, &J)) continue;
      const Vec2 r = (uv - o.uv) * o.inv_sigma;
      double rho, w;
      loss_.evaluate(r.squaredNorm(), rho, w);
      const Mat23 Jp = o.inv_sigma * J * rig_.T_b_c(o.cam).R.transpose() * kf_T_[o.kf].R.transpose();
      H.noalias() += w * Jp.transpose() * Jp;
      g.noalias() += w * Jp.transpose() * r;
    }
    H.diagonal().array() += 1e-9 + 1e-6 * H.diagonal().array();  // a ray pair without parallax stays put
    const Vec3 dp = H.ldlt().solve(-g);
    if (!dp.allFinite()) break;
    p += dp;
  }
  double c = 0;
  for (int i = begin; i < end; ++i) {
    const Obs& o = obs_[i];
    Vec2 uv;
    if (!rig_.model(o.cam).project(cameraPoint(o), uv)) {
      c += missing;
      continue;
    }
    c += loss_.rho(((uv - o.uv) * o.inv_sigma).squaredNorm());
  }
  return 0.5 * c;
}

double ScaleEstimator::cost() {
  double c = 0;
  for (int l = 0; l < nl_; ++l) {
    Vec3 p = lm_p_[l];
    c += landmarkCost(l, p);
  }
  return c;
}

void ScaleEstimator::scaleWindow(double s) {
  for (int w = 0; w < nk_; ++w) kf_T_[w].t *= s;
  for (int l = 0; l < nl_; ++l) lm_p_[l] *= s;
}

void ScaleEstimator::saveWindow(std::vector<SE3>& kf, std::vector<Vec3>& lm) const {
  std::copy_n(kf_T_.begin(), nk_, kf.begin());
  std::copy_n(lm_p_.begin(), nl_, lm.begin());
}

void ScaleEstimator::restoreWindow(const std::vector<SE3>& kf, const std::vector<Vec3>& lm) {
  std::copy_n(kf.begin(), nk_, kf_T_.begin());
  std::copy_n(lm.begin(), nl_, lm_p_.begin());
}

// Levenberg-Marquardt over the free keyframe poses; the landmarks follow (re-fitted in every cost and system).
class ScaleEstimator::Problem final : public backend::LeastSquaresProblem {
 public:
  explicit Problem(ScaleEstimator& e) : e_(e), c_(e.cost()) {}
  bool linearize() override {
    double chi2 = 0;
    int residuals = 0;
    if (!e_.reducedSystem(chi2, residuals)) return false;
    std::copy_n(e_.kf_T_.begin(), e_.nk_, e_.kf_before_.begin());
    return true;
  }
  double cost() const override { return c_; }
  void buildDampedSystem(double mu) override { mu_ = mu; }
  bool solveStep() override { return e_.dampedStep(mu_, step_); }
  double stepNorm() const override { return step_.norm(); }
  double modelCostDecrease(double) const override { return -(e_.b_.dot(step_) + 0.5 * step_.dot(e_.S_ * step_)); }
  bool evaluateTrial(double& cost) override {
    for (int w = 0; w < e_.nk_; ++w) {
      const int f = e_.freeIndex(w);
      if (f >= 0) e_.kf_T_[w] = e_.kf_before_[w] * SE3::exp(step_.segment<6>(6 * f));
    }
    cost = trial_ = e_.cost();
    return true;
  }
  void acceptTrial() override {
    c_ = trial_;
    u_step_ = e_.g_.dot(step_);
  }
  void rejectTrial() override { std::copy_n(e_.kf_before_.begin(), e_.nk_, e_.kf_T_.begin()); }
  double uStep() const { return u_step_; }

 private:
  ScaleEstimator& e_;
  double c_, trial_ = 0, mu_ = 0, u_step_ = 0;
  ReducedVec step_;
};

bool ScaleEstimator::refine(int steps, double& c, double& u_step, int* taken) {
  // The trust region from mu = 1e-6; ten refusals in a row (each re-fits every landmark) end it: the window is at
  // its minimum.
  backend::LoopOptions loop;
  loop.damping = backend::DampingPolicy::trustRegion(kInitialRadius);
  loop.max_steps = steps;
  loop.max_consecutive_rejections = kMaxRefusals;
  Problem problem(*this);
  const backend::LoopSummary summary = backend::minimize(problem, loop);
  c = problem.cost();
  u_step = problem.uStep();
  if (taken) *taken = summary.steps;
  return !summary.failed;
}

bool ScaleEstimator::refineNearUnit(double& c, double& u_step) {
  const double scale_before = scaleOfPoses();
  saveWindow(kf_start_, lm_start_);
  int taken = 0;
  if (refine(kRefineSteps, c, u_step, &taken) && taken > 0 &&
      std::abs(std::log(scaleOfPoses() / scale_before)) <= std::log(kProfileRatio)) {
    return true;
  }
  restoreWindow(kf_start_, lm_start_);
  return false;
}

double ScaleEstimator::scaleOfPoses() const {
  double sum = 0;
  for (int w = 0; w < nk_; ++w) sum += (kf_T_[w].t - kf_T_[oldest_].t).norm();
  return sum;
}

bool ScaleEstimator::reducedSystem(double& chi2, int& residuals) {
  const int dim = 6 * (nk_ - 1);
  S_.setZero(dim, dim);
  b_.setZero(dim);
  chi2 = 0;
  residuals = 0;
  SE3 T_b_w[kMaxKeyframes];
  for (int w = 0; w < nk_; ++w) T_b_w[w] = kf_T_[w].inverse();
  for (int l = 0; l < nl_; ++l) {
    Vec3 p = lm_p_[l];
    landmarkCost(l, p);  // the landmark's best position for these poses
    lm_p_[l] = p;
    Mat3 Hll = Mat3::Zero();
    Vec3 bl = Vec3::Zero();
    schur_.beginPoint();
    for (int i = lm_first_[l]; i < lm_first_[l + 1]; ++i) {
      const Obs& o = obs_[i];
      Vec2 r;
      backend::ReprojectionJacobians J;
      if (!backend::reprojectionResidualInverse(rig_.model(o.cam), T_b_w[o.kf], T_c_b_[o.cam], p, o.uv, o.inv_sigma, r,
                                                &J)) {
        continue;
      }
      double rho, wt;
      loss_.evaluate(r.squaredNorm(), rho, wt);
      chi2 += rho;
      ++residuals;
      Hll.noalias() += wt * J.point.transpose() * J.point;
      bl.noalias() += wt * J.point.transpose() * r;
      const int f = freeIndex(o.kf);
      if (f < 0 || schur_.full()) continue;
      S_.block<6, 6>(6 * f, 6 * f).noalias() += wt * J.pose.transpose() * J.pose;
      b_.segment<6>(6 * f).noalias() += wt * J.pose.transpose() * r;
      schur_.appendCoupling(f) = wt * J.pose.transpose() * J.point;
    }
    Hll.diagonal().array() += 1e-9;
    const Mat3 Hinv = Hll.inverse();
    if (!Hinv.allFinite()) continue;
    schur_.eliminate(Hinv, bl, S_, b_);
  }
  // Scale gradient: u = log(sum of |t_i - t_oldest|), right perturbation moves t_i by R_i rho.
  const double sum = scaleOfPoses();
  g_.setZero(dim);
  if (!(sum > 0)) return false;
  for (int w = 0; w < nk_; ++w) {
    const int f = freeIndex(w);
    const Vec3 d = kf_T_[w].t - kf_T_[oldest_].t;
    if (f >= 0 && d.norm() > 0) g_.segment<3>(6 * f) = kf_T_[w].R.transpose() * d / (d.norm() * sum);
  }
  // The variance of u (in units of the pixel sigmas) from the undamped system. The damping of dampedStep() only
  // steadies the step: where the window does not constrain the scale it would pose as information.
  const Eigen::LDLT<Reduced> exact(S_);
  scale_variance_ = exact.info() == Eigen::Success ? g_.dot(exact.solve(g_)) : INFINITY;
  if (!(scale_variance_ > 0)) scale_variance_ = INFINITY;  // singular or indefinite: the scale is not observed
  if (hold_scale_) {                                       // a stiff prior keeps u where the profile put it
    constexpr double kHoldWeight = 1e10;
    S_.noalias() += kHoldWeight * g_ * g_.transpose();
    b_.noalias() += kHoldWeight * (std::log(sum) - held_u_) * g_;
  }
  return b_.allFinite() && std::isfinite(scale_variance_);
}

bool ScaleEstimator::dampedStep(double mu, ReducedVec& step) {
  backend::dampedMatrix(S_, mu, damped_);
  const Eigen::LDLT<Reduced> ldlt(damped_);
  if (ldlt.info() != Eigen::Success) return false;
  step = ldlt.solve(-b_);
  return step.allFinite();
}

// The window: the map's newest live keyframes (up to kMaxKeyframes), the back-end's and the older ones kept for
// tracking: a window that spans a whole turn sees the lever arms move most. The oldest is the centre, held.
// False when there are too few (or the map is not the one the estimator was sized for).
bool ScaleEstimator::selectWindow(const Map& map, ScaleEstimate& out) {
  for (int c = 0; c < rig_.size(); ++c) T_c_b_[c] = rig_.T_b_c(c).inverse();
  if (map.keyframeCapacity() > static_cast<int>(kf_slot_of_.size())) return false;  // not the map it was sized for
  std::fill(kf_slot_of_.begin(), kf_slot_of_.end(), -1);
  int live = 0;
  for (int i = 0; i < map.keyframeCapacity(); ++i) {
    if (map.keyframe(i).alive) kf_order_[live++] = i;
  }
  nk_ = std::min(live, kMaxKeyframes);
  out.keyframes = nk_;
  if (nk_ < 3) return false;
  auto newer = [&](int a, int b) { return map.keyframe(a).id > map.keyframe(b).id; };
  std::nth_element(kf_order_.begin(), kf_order_.begin() + (nk_ - 1), kf_order_.begin() + live, newer);
  int oldest = kf_order_[0], newest = kf_order_[0];
  for (int w = 0; w < nk_; ++w) {
    const int i = kf_order_[w];
    kf_slot_of_[i] = w;
    if (newer(oldest, i)) oldest = i;
    if (newer(i, newest)) newest = i;
  }
  out.center = map.keyframe(oldest).T_w_b.t;
  oldest_ = kf_slot_of_[oldest];
  out.oldest_id = map.keyframe(oldest).id;
  out.oldest_slot = oldest;
  out.oldest_frame = map.keyframe(oldest).frame_index;
  out.newest_id = map.keyframe(newest).id;
  for (int w = 0; w < nk_; ++w) {
    kf_T_[w] = map.keyframe(kf_order_[w]).T_w_b;
    kf_T_[w].t -= out.center;
  }
  return true;
}

int ScaleEstimator::windowViews(const Landmark& L) const {
  uint32_t seen_by = 0;  // bit per window keyframe
  for (int j = 0; j < L.obs_count; ++j) {
    const int w = kf_slot_of_[L.obs[j].keyframe];
    if (w >= 0) seen_by |= 1u << w;
  }
  return std::popcount(seen_by);
}

// Landmarks seen from at least three window keyframes, with their window observations. A landmark of two
// keyframes was created by an epipolar search at the map's poses: its two rays were chosen because they meet
// there, so it agrees with the map's unit whether or not it is a lookalike. A third keyframe's observation is a
// test it could fail. The profile's share comes first: every stride-th of them, an even sample that keeps the
// near points, which tell the scale best.
bool ScaleEstimator::collectLandmarks(const Map& map, const Vec3& center) {
  // One pass over the map's pool. eligible_ holds min(max_landmarks, the window's keypoints) slots
  // (ScaleSupervisor) and each landmark listed owns at least kMinLandmarkKeyframes of the window's keypoints, so
  // only a map the estimator was not sized for fills it.
  int eligible = 0;
  for (int lm = 0; lm < map.landmarkCapacity(); ++lm) {
    const Landmark& L = map.landmark(lm);
    if (!L.alive || windowViews(L) < kMinLandmarkKeyframes) continue;
    if (eligible == static_cast<int>(eligible_.size())) return false;
    eligible_[eligible++] = lm;
  }
  const int stride = std::max(1, (eligible + kProfileLandmarks - 1) / kProfileLandmarks);
  nl_ = 0;
  no_ = 0;
  appendLandmarks(map, center, eligible, stride, true);
  np_ = nl_;
  if (stride > 1) appendLandmarks(map, center, eligible, stride, false);
  lm_first_[nl_] = no_;
  return true;
}

void ScaleEstimator::appendLandmarks(const Map& map, const Vec3& center, int eligible, int stride, bool profile_share) {
  for (int e = 0; e < eligible && nl_ < static_cast<int>(lm_p_.size()); ++e) {
    if ((e % stride == 0) != profile_share) continue;
    const Landmark& L = map.landmark(eligible_[e]);
    int n = 0;
    for (int j = 0; j < L.obs_count; ++j) n += kf_slot_of_[L.obs[j].keyframe] >= 0 ? 1 : 0;
    if (no_ + n > static_cast<int>(obs_.size())) continue;
    lm_first_[nl_] = no_;
    for (int j = 0; j < L.obs_count; ++j) {
      const int w = kf_slot_of_[L.obs[j].keyframe];
      if (w < 0) continue;
      const Keypoint& kp = map.keyframe(L.obs[j].keyframe).features.sets[L.obs[j].cam].keypoints[L.obs[j].kp];
      const int octave = std::clamp<int>(kp.octave, 0, static_cast<int>(octave_sigma_.size()) - 1);
      obs_[no_++] = Obs{static_cast<int16_t>(w), L.obs[j].cam, Vec2(kp.x, kp.y), 1.0 / octave_sigma_[octave]};
    }
    lm_p_[nl_] = L.p_w - center;
    ++nl_;
  }
}

// The profile of the cost over log s in [-log max_ratio, log max_ratio], from the map's unit outwards both ways;
// each factor starts from its neighbour's re-fitted window, scaled. Leaves the window at the best factor; false
// when the best is at the end of the range (no minimum inside: the window says nothing).
bool ScaleEstimator::profileScale(double max_ratio) {
  const double umax = std::log(max_ratio);
  const int steps = std::max(2, static_cast<int>(std::ceil(umax / std::log(kProfileRatio))));
  const double du = umax / steps;
  saveWindow(kf_start_, lm_start_);
  hold_scale_ = true;
  int best = 0;
  double best_cost = std::numeric_limits<double>::infinity();
  for (const int dir : {1, -1}) {
    restoreWindow(kf_start_, lm_start_);
    for (int k = dir > 0 ? 0 : 1; k <= steps; ++k) {
      if (k > 0) scaleWindow(std::exp(dir * du));
      held_u_ = std::log(scaleOfPoses());
      double c = 0, u_step = 0;
      if (!refine(kProfileSteps, c, u_step)) break;
      if (c < best_cost) {
        best_cost = c;
        best = dir * k;
        saveWindow(kf_best_, lm_best_);
      }
    }
  }
  hold_scale_ = false;
  if (best == -steps || best == steps) return false;  // no minimum inside the range: the window says nothing
  restoreWindow(kf_best_, lm_best_);
  return true;
}

bool ScaleEstimator::prepare(const Map& map, ScaleEstimate& out) {
  out = ScaleEstimate{};
  if (!selectWindow(map, out) || !collectLandmarks(map, out.center)) return false;
  out.landmarks = nl_;
  out.observations = no_;
  return nl_ >= 20;
}

void ScaleEstimator::solve(double max_ratio, bool unit_known, ScaleEstimate& out) {
  const double scale_before = scaleOfPoses();
  if (!(scale_before > 0)) return;
  double c = 0, last_u_step = 0, chi2 = 0;
  int residuals = 0;
  // A known unit is refined from where it is; a refinement that finds no minimum near it (a window the map's
  // last steps distorted, whose fit would otherwise pass for a precise estimate) gets the coarse search.
  const bool refined = unit_known && max_ratio > 1.0 && refineNearUnit(c, last_u_step);

  if (!refined) {
    // 1. Coarse (max_ratio > 1): the profile brings a map whose unit is far off into the basin. It only chooses
    //    the basin: a sample of the landmarks is enough for that (it re-fits the window at every factor it tries),
    //    and the others then take the factor it chose.
    if (max_ratio > 1.0) {
      const int all = nl_;
      nl_ = np_;
      const bool found = profileScale(max_ratio);
      const double factor = scaleOfPoses() / scale_before;
      nl_ = all;
      if (!found) return;
      for (int l = np_; l < nl_; ++l) lm_p_[l] *= factor;
    }
    // 2. Fine: Levenberg-Marquardt on the whole window, the scale free.
    if (!refine(kRefineSteps, c, last_u_step)) return;
  }
  // The last system gives the marginal sigma.
  if (!reducedSystem(chi2, residuals)) return;
  // A refinement that still moved the scale by more than its sigma has not found the window's minimum: its
  // curvature says nothing about the scale.
  if (!(last_u_step * last_u_step <= scale_variance_)) return;
  const double dof = std::max(1.0, 2.0 * residuals - 3.0 * nl_ - 6.0 * (nk_ - 1));
  out.reduced_chi2 = chi2 / dof;
  const double reduced = std::max(1.0, out.reduced_chi2);
  const double variance = scale_variance_ * reduced;
  if (!(variance > 0)) return;
  out.scale = scaleOfPoses() / scale_before;
  out.relative_sigma = std::sqrt(variance);
  out.ok = std::isfinite(out.scale) && out.scale > 0;
}

ScaleEstimate ScaleEstimator::estimate(const Map& map, double max_ratio) {
  ScaleEstimate out;
  if (prepare(map, out)) solve(max_ratio, false, out);
  return out;
}

bool ScaleFilter::add(double log_scale, double sigma, int64_t oldest_id, int64_t newest_id, double rotation) {
  const double info_new = 1.0 / (sigma * sigma);
  if (!std::isfinite(log_scale) || !(info_new > 0) || !std::isfinite(info_new)) return false;
  if (last_newest_ >= 0 && newest_id > last_newest_ && drift_variance_ > 0) {
    const double q = drift_variance_ * static_cast<double>(newest_id - last_newest_);
    for (Part* p : {&committed_, &pending_}) {
      if (p->info > 0) p->info = 1.0 / (1.0 / p->info + q);
    }
  }
  last_newest_ = std::max(last_newest_, newest_id);
  const double x = correction();
  if (info() > 0 && (log_scale - x) * (log_scale - x) > 9.0 * (sigma * sigma + 1.0 / info())) {
    // One window off by 3 sigma is an outlier; several in a row mean the map's scale moved. Once converged,
    // they must include two that share no keyframe: overlapping windows in a map a fast corner broke agree with
    // each other.
    if (rejected_++ == 0) first_rejected_newest_ = newest_id;
    const bool independent = drift_variance_ == 0 || oldest_id > first_rejected_newest_;
    if (rejected_ < kRestartAfter || !independent) return false;
    committed_ = pending_ = Part{};
  }
  rejected_ = 0;
  if (info() == 0) first_rotation_ = rotation;
  last_rotation_ = rotation;
  if (pending_.info > 0 && oldest_id > pending_newest_) {  // no keyframe shared: the pending window is final
    committed_ = fuse(committed_, pending_);
    pending_ = Part{};
  }
  if (drift_variance_ > 0 && committed_.info > 0 && sigma * sigma * committed_.info < 1.0) {
    // The unit does not only random-walk: it jumps where the scene leaves the rig one camera looking ahead (side
    // cameras before blank walls). A window more
    // certain than the committed part that disagrees with it by more than both sigmas allow raises the committed
    // variance to what the disagreement shows (covariance matching). Only then: a turn's first windows, less
    // certain, often disagree with both.
    const double nu = log_scale - committed_.x, excess = nu * nu - sigma * sigma;
    if (excess * committed_.info > 1.0) committed_.info = 1.0 / excess;
  }
  if (info_new >= pending_.info) {
    pending_ = Part{log_scale, info_new};
    pending_newest_ = newest_id;
  }
  return true;
}

}  // namespace mcslam
