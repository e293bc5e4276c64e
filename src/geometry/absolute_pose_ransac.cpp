#include "mcslam/geometry/absolute_pose_ransac.hpp"

#include <cmath>
#include <limits>

#include "mcslam/geometry/generalized_p3p.hpp"

namespace mcslam {

namespace {

// The refinement inside RANSAC only polishes the winner: the caller runs the full robust refinement.
PoseRefinementOptions winnerRefinement(const AbsolutePoseRansacOptions& o) {
  PoseRefinementOptions r;
  r.rounds = 2;
  r.iterations_per_round = 8;
  r.robust_rounds = 1;
  r.chi2_threshold = o.chi2_threshold;
  r.min_inliers = std::max(o.min_inliers, 3);
  return r;
}

}  // namespace

const char* absolutePoseStatusName(AbsolutePoseStatus s) {
  switch (s) {
    case AbsolutePoseStatus::Ok: return "ok";
    case AbsolutePoseStatus::TooFewCorrespondences: return "too_few_correspondences";
    case AbsolutePoseStatus::OverCapacity: return "over_capacity";
    case AbsolutePoseStatus::NoConsensus: return "no_consensus";
  }
  return "?";
}

AbsolutePoseRansac::AbsolutePoseRansac(const Rig& rig, int capacity, const AbsolutePoseRansacOptions& options)
    : rig_(rig),
      options_(options),
      refiner_(rig, capacity, winnerRefinement(options)),
      random_(options.seed),
      T_c_w_(rig.size()),
      inliers_(static_cast<size_t>(std::max(capacity, 0)), 0) {}

double AbsolutePoseRansac::score(std::span<const PoseObservation> obs, const SE3& T_w_b, double bail_out) {
  const SE3 T_b_w = T_w_b.inverse();
  for (int c = 0; c < rig_.numCameras(); ++c) T_c_w_[c] = rig_.T_c_b(c) * T_b_w;
  const double cap = options_.chi2_threshold;
  const double threshold_sigmas = std::sqrt(cap);
  double cost = 0;
  for (const PoseObservation& o : obs) {
    double s = cap;
    if (o.camera >= 0 && o.camera < rig_.numCameras()) {
      // Cheap rejection first: a direction further from the keypoint's ray than the threshold
      // allows in the worst corner of the lens cannot reproject within it (most points, for the
      // many wrong hypotheses). cos(a) >= 1 - a^2 / 2 keeps the test conservative.
      const Vec3 v = T_b_w * o.point_w - o.ray.origin;
      const double max_angle = threshold_sigmas * o.sigma_px * rig_.maxRadiansPerPixel(o.camera);
      const bool near_ray =
          max_angle >= 1.0 || v.dot(o.ray.direction) >= (1.0 - 0.5 * max_angle * max_angle) * v.norm();
      Vec2 uv;
      if (near_ray && rig_.model(o.camera).project(T_c_w_[o.camera] * o.point_w, uv)) {
        s = std::min(cap, (uv - o.pixel).squaredNorm() / (o.sigma_px * o.sigma_px));
      }
    }
    cost += s;
    if (cost >= bail_out) return cost;
  }
  return cost;
}

int AbsolutePoseRansac::classify(std::span<const PoseObservation> obs, const SE3& T_w_b) {
  const SE3 T_b_w = T_w_b.inverse();
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

AbsolutePoseRansacResult AbsolutePoseRansac::estimate(std::span<const PoseObservation> obs,
                                                      const SE3* predicted_T_w_b) {
  AbsolutePoseRansacResult result;
  const int n = static_cast<int>(obs.size());
  if (n > capacity()) {
    result.status = AbsolutePoseStatus::OverCapacity;
    return result;
  }
  if (n < 3 || n < options_.min_inliers) return result;

  double best_cost = std::numeric_limits<double>::infinity();
  SE3 best;
  bool have_best = false;
  auto consider = [&](const SE3& T_w_b, bool prediction) {
    const double c = score(obs, T_w_b, best_cost);
    if (c >= best_cost) return false;
    best_cost = c;
    best = T_w_b;
    have_best = true;
    result.from_prediction = prediction;
    return true;
  };

  if (predicted_T_w_b) consider(*predicted_T_w_b, true);
  int needed = options_.max_iterations;
  auto updateNeeded = [&] {
    const int inl = classify(obs, best);
    needed = std::min(options_.max_iterations, ransacIterationsNeeded(double(inl) / n, 3, options_.confidence));
  };
  if (have_best) updateNeeded();

  GeneralizedP3PSolutions solutions;
  int iterations = 0;
  while (iterations < needed) {
    ++iterations;
    int idx[3];
    random_.distinct(n, 3, idx);
    const std::array<BodyRay, 3> rays{obs[idx[0]].ray, obs[idx[1]].ray, obs[idx[2]].ray};
    const std::array<Vec3, 3> points{obs[idx[0]].point_w, obs[idx[1]].point_w, obs[idx[2]].point_w};
    const int count = solveGeneralizedP3P(rays, points, solutions);
    bool improved = false;
    for (int s = 0; s < count; ++s) improved = consider(solutions.T_w_b[s], false) || improved;
    if (improved) updateNeeded();
  }
  result.iterations = iterations;
  if (!have_best) {
    result.status = AbsolutePoseStatus::NoConsensus;
    return result;
  }

  int num_inliers = classify(obs, best);
  if (options_.refine && num_inliers >= 3) {
    const PoseRefinementResult refined = refiner_.refine(obs, best, std::span<const uint8_t>(inliers_.data(), n));
    // Keep the refinement unless it loses consensus (fewer inliers and a worse MSAC cost).
    if (refined.success) {
      const int refined_inliers = classify(obs, refined.T_w_b);
      if (refined_inliers >= num_inliers ||
          score(obs, refined.T_w_b, std::numeric_limits<double>::infinity()) <= best_cost) {
        best = refined.T_w_b;
      }
    }
    num_inliers = classify(obs, best);
  }
  if (options_.refine && predicted_T_w_b) {
    // Against the winner (see the header): the near points a nearly degenerate winner lost decide.
    const PoseRefinementResult refined = refiner_.refine(obs, *predicted_T_w_b);
    if (refined.success) {
      const int refined_inliers = classify(obs, refined.T_w_b);
      if (refined_inliers > num_inliers) {
        best = refined.T_w_b;
        num_inliers = refined_inliers;  // inliers_ holds its classification
        result.from_prediction = true;
      } else {
        num_inliers = classify(obs, best);
      }
    }
  }
  result.T_w_b = best;
  result.num_inliers = num_inliers;
  result.inlier_mask = std::span<const uint8_t>(inliers_.data(), n);
  result.status = num_inliers >= options_.min_inliers ? AbsolutePoseStatus::Ok : AbsolutePoseStatus::NoConsensus;
  return result;
}

}  // namespace mcslam
