#include "mcslam/geometry/pose_refinement.hpp"

#include <Eigen/Cholesky>
#include <cmath>

namespace mcslam {

namespace {

// Huber loss of a squared whitened error s, threshold k (in sigmas).
double huberLoss(double s, double k) { return s <= k * k ? s : 2.0 * k * std::sqrt(s) - k * k; }
double huberWeight(double s, double k) { return s <= k * k ? 1.0 : k / std::sqrt(s); }

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
  int round = 0;
  for (; round < options_.rounds; ++round) {
    const bool robust = robustRound(round);
    double lambda = 1e-4;
    for (int it = 0; it < options_.iterations_per_round; ++it) {
      // Levenberg-Marquardt: damp until the cost goes down. A step too small to matter ends the
      // round at once (each refused trial costs a full pass over the observations).
      bool improved = false, converged = false;
      for (int trial = 0; trial < 8 && !improved && !converged; ++trial) {
        Mat6 A = current.H;
        A.diagonal() += lambda * (current.H.diagonal().array() + 1e-12).matrix();
        const Vec6 delta = A.ldlt().solve(-current.g);
        if (!delta.allFinite()) break;
        converged = delta.norm() < 1e-9;
        ++result.iterations;
        const SE3 candidate = T_w_b * SE3::exp(delta);
        const Pass trial_pass = evaluate(obs, candidate.inverse(), robust, false, true);
        if (trial_pass.cost < current.cost) {
          converged = converged || current.cost - trial_pass.cost < 1e-9 * current.cost;
          T_w_b = candidate;
          current = trial_pass;
          lambda = std::max(lambda * 0.2, 1e-9);
          improved = true;
        } else {
          lambda *= 10.0;
        }
      }
      if (!improved || converged) break;
    }
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
