#include "mcslam/geometry/pose_refinement.hpp"

#include <Eigen/Cholesky>
#include <cmath>

#include "mcslam/backend/levenberg_marquardt.hpp"

namespace mcslam {

namespace {

// Huber loss of a squared whitened error s, threshold k (in sigmas).
double huberLoss(double s, double k) { return s <= k * k ? s : 2.0 * k * std::sqrt(s) - k * k; }
double huberWeight(double s, double k) { return s <= k * k ? 1.0 : k / std::sqrt(s); }

// The trust region from 1e4 (mu = 1e-4) each round; a round ends after eight refusals in a row (each costs a
// full pass over the observations), after a step too small to matter or one that lowered the cost by less than
// a billionth.
backend::LoopOptions loopOptions(const PoseRefinementOptions& options) {
  backend::LoopOptions loop;
  loop.damping = backend::DampingPolicy::trustRegion(1e4);
  loop.max_steps = options.iterations_per_round;
  loop.max_consecutive_rejections = 8;
  loop.function_tolerance = 1e-9;
  loop.small_step = backend::LoopOptions::SmallStep::EndsAfterTrial;
  loop.min_step_norm = 1e-9;
  loop.stop_on_failed_solve = true;
  return loop;
}

}  // namespace

PoseRefiner::PoseRefiner(const Rig& rig, int capacity, const PoseRefinementOptions& options)
    : rig_(rig), options_(options), inliers_(static_cast<size_t>(std::max(capacity, 0)), 0) {}

// One pass over the observations at T_b_w. With `reclassify`, every observation is first marked inlier or not
// by its chi-square error there; then over the inliers: the (Huber or plain) cost, and with `linearize` the
// normal equations with the iteratively reweighted whitened residuals. Gross errors and points that do not
// project cost the same constant and give no gradient: no step gains by pushing a point out of its camera's
// domain. Fusing these keeps one pass per Levenberg-Marquardt trial: an accepted trial's pass is already the
// next iteration's linearization.
PoseRefiner::Pass PoseRefiner::evaluate(std::span<const PoseObservation> obs, const SE3& T_b_w, bool robust,
                                        bool reclassify, bool linearize) {
  const double k = options_.huber_threshold;
  const double gross2 = options_.gross_error_sigmas * options_.gross_error_sigmas;
  const double gross_cost = robust ? huberLoss(gross2, k) : gross2;
  Pass pass;
  for (size_t i = 0; i < obs.size(); ++i) {
    if (!reclassify && !inliers_[i]) continue;
    Vec2 r;
    Mat26 J;
    const double var = obs[i].sigma_px * obs[i].sigma_px;
    const bool projects = rig_.residual(T_b_w, obs[i], r, linearize ? &J : nullptr);
    if (reclassify) {
      const bool in = projects && r.squaredNorm() < options_.chi2_threshold * var;
      inliers_[i] = in ? 1 : 0;
      if (!in) continue;
      ++pass.inliers;
    }
    const double s = projects ? r.squaredNorm() / var : gross2;
    pass.cost += s >= gross2 ? gross_cost : (robust ? huberLoss(s, k) : s);
    if (!linearize || s >= gross2) continue;
    const double inv_var = 1.0 / var;
    const double s_w = r.squaredNorm() * inv_var;
    pass.squares += s_w;
    const double w = inv_var * (robust ? huberWeight(s_w, k) : 1.0);
    pass.H.noalias() += w * J.transpose() * J;
    pass.g.noalias() += w * J.transpose() * r;
  }
  return pass;
}

// Levenberg-Marquardt on the pose at one outlier classification: the current pass is the linearization at
// T_w_b, and an accepted trial's pass is already the next one.
class PoseRefiner::Problem final : public backend::LeastSquaresProblem {
 public:
  Problem(PoseRefiner& refiner, std::span<const PoseObservation> obs, SE3& T_w_b, Pass& current, bool robust)
      : refiner_(refiner), obs_(obs), T_w_b_(T_w_b), current_(current), robust_(robust) {}
  bool linearize() override { return true; }
  double cost() const override { return current_.cost; }
  void buildDampedSystem(double mu) override { backend::dampedMatrix(current_.H, mu, A_); }
  bool solveStep() override {
    delta_ = A_.ldlt().solve(-current_.g);
    return delta_.allFinite();
  }
  double stepNorm() const override { return delta_.norm(); }
  double modelCostDecrease(double) const override {
    return -(current_.g.dot(delta_) + 0.5 * delta_.dot(current_.H * delta_));
  }
  bool evaluateTrial(double& cost) override {
    candidate_ = T_w_b_ * SE3::exp(delta_);
    trial_ = refiner_.evaluate(obs_, candidate_.inverse(), robust_, false, true);
    cost = trial_.cost;
    return true;
  }
  void acceptTrial() override {
    T_w_b_ = candidate_;
    current_ = trial_;
  }

 private:
  PoseRefiner& refiner_;
  std::span<const PoseObservation> obs_;
  SE3& T_w_b_;
  Pass& current_;
  const bool robust_;
  Mat6 A_;
  Vec6 delta_;
  SE3 candidate_;
  Pass trial_;
};

PoseRefinementResult PoseRefiner::refine(std::span<const PoseObservation> obs, const SE3& initial_T_w_b,
                                         std::span<const uint8_t> initial_inliers) {
  PoseRefinementResult result;
  result.T_w_b = initial_T_w_b;
  const size_t n = obs.size();
  if (n > inliers_.size() || (!initial_inliers.empty() && initial_inliers.size() != n)) return result;

  for (size_t i = 0; i < n; ++i) inliers_[i] = initial_inliers.empty() ? 1 : (initial_inliers[i] ? 1 : 0);
  SE3 T_w_b = initial_T_w_b;
  auto robustRound = [&](int round) { return round < options_.robust_rounds; };
  Pass current = evaluate(obs, T_w_b.inverse(), robustRound(0), false, true);
  const backend::LoopOptions loop = loopOptions(options_);
  int round = 0;
  for (; round < options_.rounds; ++round) {
    Problem problem(*this, obs, T_w_b, current, robustRound(round));
    result.iterations += backend::minimize(problem, loop).trials;
    T_w_b.normalize();
    // The inliers of the next round, its cost and normal equations at the round's pose in one pass; after
    // the last round (or too few inliers) a plain pass: the result's cost and information.
    const bool last = round + 1 == options_.rounds;
    current = evaluate(obs, T_w_b.inverse(), !last && robustRound(round + 1), true, true);
    if (current.inliers < options_.min_inliers) break;
  }
  if (options_.rounds <= 0) {
    current = evaluate(obs, T_w_b.inverse(), false, true, true);
  } else if (round + 1 < options_.rounds && robustRound(round + 1)) {  // stopped early after a robust pass
    const int inliers = current.inliers;
    current = evaluate(obs, T_w_b.inverse(), false, false, true);
    current.inliers = inliers;
  }

  result.num_inliers = current.inliers;
  result.T_w_b = T_w_b;
  result.cost = current.squares;
  result.information = current.H;
  result.mean_chi2 = result.num_inliers > 0 ? result.cost / result.num_inliers : 0.0;
  result.success = result.num_inliers >= options_.min_inliers && T_w_b.R.allFinite() && T_w_b.t.allFinite();
  result.inlier_mask = std::span<const uint8_t>(inliers_.data(), n);
  return result;
}

}  // namespace mcslam
