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

double PoseRefiner::robustCost(std::span<const PoseObservation> obs, const SE3& T_b_w, bool robust) const {
  const double k = options_.huber_threshold;
  const double gross2 = options_.gross_error_sigmas * options_.gross_error_sigmas;
  // Gross errors and points that do not project cost the same constant: no step gains by
  // pushing a point out of its camera's domain.
  const double gross_cost = robust ? huberLoss(gross2, k) : gross2;
  double cost = 0;
  for (size_t i = 0; i < obs.size(); ++i) {
    if (!inliers_[i]) continue;
    Vec2 r;
    const double s = rig_.residual(T_b_w, obs[i], r) ? r.squaredNorm() / (obs[i].sigma_px * obs[i].sigma_px) : gross2;
    cost += s >= gross2 ? gross_cost : (robust ? huberLoss(s, k) : s);
  }
  return cost;
}

int PoseRefiner::classify(std::span<const PoseObservation> obs, const SE3& T_b_w) {
  int count = 0;
  for (size_t i = 0; i < obs.size(); ++i) {
    Vec2 r;
    const bool in = rig_.residual(T_b_w, obs[i], r) &&
                    r.squaredNorm() < options_.chi2_threshold * obs[i].sigma_px * obs[i].sigma_px;
    inliers_[i] = in ? 1 : 0;
    count += in ? 1 : 0;
  }
  return count;
}

PoseRefinementResult PoseRefiner::refine(std::span<const PoseObservation> obs, const SE3& initial_T_w_b,
                                         std::span<const uint8_t> initial_inliers) {
  PoseRefinementResult result;
  result.T_w_b = initial_T_w_b;
  const size_t n = obs.size();
  if (n > inliers_.size() || (!initial_inliers.empty() && initial_inliers.size() != n)) return result;

  for (size_t i = 0; i < n; ++i) inliers_[i] = initial_inliers.empty() ? 1 : (initial_inliers[i] ? 1 : 0);
  SE3 T_w_b = initial_T_w_b;
  const double k = options_.huber_threshold;
  const double gross2 = options_.gross_error_sigmas * options_.gross_error_sigmas;

  for (int round = 0; round < options_.rounds; ++round) {
    const bool robust = round < options_.robust_rounds;
    SE3 T_b_w = T_w_b.inverse();
    double cost = robustCost(obs, T_b_w, robust);
    double lambda = 1e-4;
    for (int it = 0; it < options_.iterations_per_round; ++it) {
      // Normal equations with iteratively reweighted (Huber) whitened residuals.
      Mat6 H = Mat6::Zero();
      Vec6 g = Vec6::Zero();
      for (size_t i = 0; i < n; ++i) {
        if (!inliers_[i]) continue;
        Vec2 r;
        Mat26 J;
        if (!rig_.residual(T_b_w, obs[i], r, &J)) continue;
        const double inv_var = 1.0 / (obs[i].sigma_px * obs[i].sigma_px);
        const double s = r.squaredNorm() * inv_var;
        if (s >= gross2) continue;  // constant cost: no gradient
        const double w = inv_var * (robust ? huberWeight(s, k) : 1.0);
        H.noalias() += w * J.transpose() * J;
        g.noalias() += w * J.transpose() * r;
      }
      // Levenberg-Marquardt: damp until the cost goes down. A step too small to matter ends the
      // round at once (each refused trial costs a full pass over the observations).
      bool improved = false, converged = false;
      for (int trial = 0; trial < 8 && !improved && !converged; ++trial) {
        Mat6 A = H;
        A.diagonal() += lambda * (H.diagonal().array() + 1e-12).matrix();
        const Vec6 delta = A.ldlt().solve(-g);
        if (!delta.allFinite()) break;
        converged = delta.norm() < 1e-9;
        ++result.iterations;
        const SE3 candidate = T_w_b * SE3::exp(delta);
        const double candidate_cost = robustCost(obs, candidate.inverse(), robust);
        if (candidate_cost < cost) {
          converged = converged || cost - candidate_cost < 1e-9 * cost;
          T_w_b = candidate;
          T_b_w = candidate.inverse();
          cost = candidate_cost;
          lambda = std::max(lambda * 0.2, 1e-9);
          improved = true;
        } else {
          lambda *= 10.0;
        }
      }
      if (!improved || converged) break;
    }
    T_w_b.normalize();
    if (classify(obs, T_w_b.inverse()) < options_.min_inliers) break;
  }

  // Final classification, cost and information at the result.
  const SE3 T_b_w = T_w_b.inverse();
  result.num_inliers = classify(obs, T_b_w);
  result.T_w_b = T_w_b;
  for (size_t i = 0; i < n; ++i) {
    if (!inliers_[i]) continue;
    Vec2 r;
    Mat26 J;
    rig_.residual(T_b_w, obs[i], r, &J);
    const double inv_var = 1.0 / (obs[i].sigma_px * obs[i].sigma_px);
    result.cost += r.squaredNorm() * inv_var;
    result.information.noalias() += inv_var * J.transpose() * J;
  }
  result.mean_chi2 = result.num_inliers > 0 ? result.cost / result.num_inliers : 0.0;
  result.success = result.num_inliers >= options_.min_inliers && T_w_b.R.allFinite() && T_w_b.t.allFinite();
  result.inlier_mask = std::span<const uint8_t>(inliers_.data(), n);
  return result;
}

}  // namespace mcslam
