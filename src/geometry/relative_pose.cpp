#include "mcslam/geometry/relative_pose.hpp"

#include <algorithm>
#include <array>

#include "mcslam/core/error.hpp"
#include "mcslam/geometry/ransac.hpp"
#include "mcslam/geometry/relative_pose_refinement.hpp"
#include "mcslam/geometry/relative_pose_solvers.hpp"

namespace mcslam {

using namespace relative_pose_detail;

namespace {

struct Refined {
  SE3 T;
  std::vector<uint8_t> mask;  // one per ray (capacity reserved by the workspace)
  int inliers = 0;
  double cost = INFINITY;  // sum of squared errors over the inliers
};

}  // namespace

// Every buffer of an estimation, sized once.
struct RelativePoseEstimator::Workspace {
  Workspace(int max_correspondences, int max_cameras) : capacity(static_cast<std::size_t>(max_correspondences)) {
    index.reserve(capacity);
    rays.reserve(capacity);
    own_rays.reserve(capacity);
    for (Refined& h : hypotheses) h.mask.reserve(capacity);
    own.mask.reserve(capacity);
    scratch_mask.reserve(capacity);
    sample_mask.reserve(capacity);
    scale_candidates.reserve(capacity + 1);
    parallax.resize(capacity);
    per_camera.resize(static_cast<std::size_t>(std::max(max_cameras, 1)));
    result.inlier_mask.reserve(capacity);
  }
  std::size_t capacity;
  std::vector<int> index;         // valid correspondences: their index in the caller's matches
  std::vector<RayPair> rays;      // and their rays
  std::vector<RayPair> own_rays;  // rotation first: the best-covered camera's rays, in its frame
  std::array<Refined, 3> hypotheses;
  Refined own;
  std::vector<uint8_t> scratch_mask, sample_mask;
  std::vector<double> scale_candidates, parallax;
  std::vector<int> per_camera;
  RelativePoseResult result;
};

namespace {

using Workspace = RelativePoseEstimator::Workspace;

// Inlier threshold on our (Sampson) angle error.
double inlierAngle(const RelativePoseOptions& o) { return o.inlier_sigmas * o.bearing_sigma_rad; }

// Correspondences with finite bearings and cameras of the rig (all of them when rig is null), normalized, as
// rays in the frames the pose is solved in.
void validMatches(std::span<const RelativeCorrespondence> matches, const Rig* rig, Workspace& ws) {
  ws.index.clear();
  ws.rays.clear();
  const std::size_t n = std::min(matches.size(), ws.capacity);
  for (std::size_t i = 0; i < n; ++i) {
    const RelativeCorrespondence& m = matches[i];
    const double n1 = m.bearing1.norm(), n2 = m.bearing2.norm();
    if (!(n1 > 0) || !(n2 > 0) || !std::isfinite(n1) || !std::isfinite(n2)) continue;
    RayPair r{Vec3::Zero(), m.bearing1 / n1, Vec3::Zero(), m.bearing2 / n2};
    if (rig) {
      if (m.camera1 < 0 || m.camera1 >= rig->size() || m.camera2 < 0 || m.camera2 >= rig->size()) continue;
      r.c1 = rig->T_b_c(m.camera1).t;
      r.d1 = rig->T_b_c(m.camera1).R * r.d1;
      r.c2 = rig->T_b_c(m.camera2).t;
      r.d2 = rig->T_b_c(m.camera2).R * r.d2;
    }
    ws.index.push_back(static_cast<int>(i));
    ws.rays.push_back(r);
  }
}

// Our refinement of one hypothesis: select inliers, refine, re-select (the set settles quickly).
// Generalized poses are refined at fixed scale first, then freely; the free step is kept only if
// it loses no inliers (where the scale is weak it slides toward t = 0 and points flip behind).
void refineHypothesis(std::span<const RayPair> rays, const SE3& start, bool central, const RelativePoseOptions& o,
                      std::vector<uint8_t>& free_mask, Refined& r) {
  r.T = start;
  if (central) r.T.t.normalize();
  r.mask.resize(rays.size());
  free_mask.resize(rays.size());
  r.inliers = selectInliers(rays, r.T, inlierAngle(o), r.mask);
  for (int round = 0; round < 3; ++round) {
    r.T = refineRelativePose(rays, r.mask, r.T, true, o);
    r.inliers = selectInliers(rays, r.T, inlierAngle(o), r.mask);
    if (central) continue;
    const SE3 free = refineRelativePose(rays, r.mask, r.T, false, o);
    const int free_inliers = selectInliers(rays, free, inlierAngle(o), free_mask);
    if (free_inliers >= r.inliers) {
      r.T = free;
      r.inliers = free_inliers;
      r.mask.swap(free_mask);
    }
  }
  r.cost = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    if (r.mask[i]) r.cost += std::pow(sampsonError(rays[i], r.T), 2);
  }
}

bool better(const Refined& a, const Refined& b) {
  return a.inliers > b.inliers || (a.inliers == b.inliers && a.cost < b.cost);
}

// Inliers, observability and status of the chosen pose, shared by both cases.
void finish(Workspace& ws, const Refined& best, bool central, const RelativePoseOptions& o, size_t num_matches) {
  RelativePoseResult& result = ws.result;
  result.T_1_2 = best.T;
  result.metric = !central;
  result.inlier_mask.assign(std::min(num_matches, ws.capacity), 0);
  result.num_inliers = best.inliers;
  for (size_t i = 0; i < best.mask.size(); ++i) result.inlier_mask[ws.index[i]] = best.mask[i];
  if (result.num_inliers < o.min_inliers) {
    result.status = RelativePoseStatus::NoConsensus;
    return;
  }
  const Observability obs = analyzeObservability(ws.rays, best.mask, best.T, central, o.bearing_sigma_rad, ws.parallax);
  result.relative_scale_sigma = central ? INFINITY : obs.relative_scale_sigma;
  result.direction_sigma_rad = obs.direction_sigma_rad;
  result.median_parallax_rad = obs.median_parallax_rad;
  if (!central && !(obs.relative_scale_sigma <= o.max_relative_scale_sigma)) {
    result.status = RelativePoseStatus::ScaleUnobservable;
  } else if (!(obs.direction_sigma_rad <= o.max_direction_sigma_rad)) {
    result.status = RelativePoseStatus::DirectionUnobservable;
  } else if (obs.median_parallax_rad < o.min_median_parallax_rad) {
    result.status = RelativePoseStatus::LowParallax;
  } else {
    result.status = RelativePoseStatus::Ok;
  }
}

// The one of an essential matrix's four poses that puts the most of the sample's points in front of both
// cameras; false unless that is all of them.
bool poseInFront(const Mat3& E, std::span<const RayPair> sample, double max_angle_rad, SE3& T) {
  Mat3 R_a, R_b;
  Vec3 t;
  decomposeEssential(E, R_a, R_b, t);
  const std::array<SE3, 4> candidates = {SE3(R_a, t), SE3(R_a, -t), SE3(R_b, t), SE3(R_b, -t)};
  int best = -1;
  for (const SE3& c : candidates) {
    const int in_front = countInliers(sample, c, max_angle_rad);
    if (in_front > best) {
      best = in_front;
      T = c;
    }
  }
  return best == static_cast<int>(sample.size());
}

// The adaptive RANSAC loop: draws samples of `k`, lets `hypotheses(sample, consider)` call consider(pose) for each
// pose the sample gives, keeps the pose with the most inliers. Returns that count (-1 without any).
template <int k, class Hypotheses>
int ransac(std::span<const RayPair> rays, const RelativePoseOptions& o, Hypotheses&& hypotheses, SE3& best_pose,
           int& iterations) {
  const int n = static_cast<int>(rays.size());
  if (n < k) return -1;
  RansacRandom random(o.seed);
  std::array<int, k> sample{};
  int best = -1;
  int needed = o.max_iterations;
  int it = 0;
  for (; it < std::min(needed, o.max_iterations); ++it) {
    random.distinct(n, k, sample.data());
    hypotheses(sample, [&](const SE3& pose) {
      const int count = countInliers(rays, pose, inlierAngle(o));
      if (count <= best) return;
      best = count;
      best_pose = pose;
      needed = ransacIterationsNeeded(static_cast<double>(count) / n, k, o.confidence);
    });
  }
  iterations += it;
  return best;
}

// 5-point RANSAC on central rays; false without consensus.
bool centralRansac(std::span<const RayPair> rays, const RelativePoseOptions& o, SE3& T, int& iterations) {
  std::array<Mat3, 10> E;
  std::array<RayPair, 5> picked;
  std::array<Vec3, 5> d1, d2;
  auto fivePoint = [&](const std::array<int, 5>& sample, auto&& consider) {
    for (int i = 0; i < 5; ++i) {
      picked[i] = rays[sample[i]];
      d1[i] = picked[i].d1;
      d2[i] = picked[i].d2;
    }
    const int solutions = fivePointEssential(d1, d2, E);
    for (int s = 0; s < solutions; ++s) {
      SE3 pose;
      if (poseInFront(E[s], picked, inlierAngle(o), pose)) consider(pose);
    }
  };
  const int inliers = ransac<5>(rays, o, fivePoint, T, iterations);
  return inliers >= std::max(8, o.min_inliers / 4);
}

// 17-point RANSAC on generalized rays; false without consensus.
bool generalizedRansac(std::span<const RayPair> rays, const RelativePoseOptions& o, std::vector<uint8_t>& sample_mask,
                       SE3& T, int& iterations) {
  sample_mask.assign(rays.size(), 0);
  std::array<SE3, 2> poses;
  auto seventeenPoint = [&](const std::array<int, 17>& sample, auto&& consider) {
    for (int i : sample) sample_mask[i] = 1;
    const bool solved = linearGeneralizedPose(rays, sample_mask, poses);
    for (int i : sample) sample_mask[i] = 0;
    if (!solved) return;
    for (const SE3& pose : poses) consider(pose);
  };
  return ransac<17>(rays, o, seventeenPoint, T, iterations) >= 17;
}

// Rotation-first hypothesis for rigs whose matches stay within cameras (where the 17-point solver
// is weakest: little rotation, non-overlapping cameras): the camera with the most matches gives
// the rotation and the direction of its own motion by the 5-point solver; the metric scale along
// that direction is then the value most matches of all cameras agree with.
bool rotationFirstHypothesis(const Rig& rig, std::span<const RelativeCorrespondence> matches,
                             const RelativePoseOptions& o, Workspace& ws, SE3& T, int& iterations) {
  std::vector<int>& count = ws.per_camera;
  std::fill(count.begin(), count.end(), 0);
  const int cameras = std::min(rig.size(), static_cast<int>(count.size()));
  for (int i : ws.index) {
    const RelativeCorrespondence& m = matches[i];
    if (m.camera1 == m.camera2 && m.camera1 < cameras) ++count[m.camera1];
  }
  const int cam = static_cast<int>(std::max_element(count.begin(), count.begin() + cameras) - count.begin());
  if (count[cam] < 16) return false;
  ws.own_rays.clear();
  for (int i : ws.index) {
    const RelativeCorrespondence& m = matches[i];
    if (m.camera1 != cam || m.camera2 != cam) continue;
    ws.own_rays.push_back({Vec3::Zero(), m.bearing1.normalized(), Vec3::Zero(), m.bearing2.normalized()});
  }
  SE3 T_c;
  if (!centralRansac(ws.own_rays, o, T_c, iterations)) return false;
  refineHypothesis(ws.own_rays, T_c, true, o, ws.scratch_mask, ws.own);
  T_c = ws.own.T;

  // Body motion as a function of the camera's unknown scale s: t(s) = t0 + s * dir.
  const SE3& T_b_c = rig.T_b_c(cam);
  const Mat3 R = T_b_c.R * T_c.R * T_b_c.R.transpose();
  const Vec3 dir = T_b_c.R * T_c.t;
  const Vec3 t0 = T_b_c.t - R * T_b_c.t;
  // Each match's error is linear in s: e = alpha s + beta; its root is a candidate scale.
  // The camera moved along +dir (the 5-point solution is in front of the camera), so s > 0. When
  // nothing fixes s (no rotation) any value fits: s = 1 is then as good as another and the
  // observability check reports it.
  std::vector<double>& candidates = ws.scale_candidates;
  candidates.assign(1, 1.0);
  for (const RayPair& p : ws.rays) {
    const double beta = sampsonError(p, SE3(R, t0));
    const double alpha = sampsonError(p, SE3(R, t0 + dir)) - beta;  // e is affine in t (normalization frozen)
    if (std::abs(alpha) > 1e-12 && -beta / alpha > 0) candidates.push_back(-beta / alpha);
  }
  RansacRandom random(o.seed);
  int best_inliers = -1;
  double best_s = 1.0;
  const int tries = std::min<int>(static_cast<int>(candidates.size()), 300);
  for (int k = 0; k < tries; ++k) {
    const double s =
        candidates.size() <= 300 ? candidates[k] : candidates[random.below(static_cast<int>(candidates.size()))];
    const int inl = countInliers(ws.rays, SE3(R, t0 + s * dir), inlierAngle(o));
    if (inl > best_inliers) {
      best_inliers = inl;
      best_s = s;
    }
  }
  T = SE3(R, t0 + best_s * dir);
  return true;
}

// The linear solver on all the inliers of the RANSAC pose: least squares over every inlier, not a minimal sample.
bool allInlierHypothesis(const SE3& ransac_pose, const RelativePoseOptions& o, Workspace& ws, SE3& T) {
  ws.sample_mask.resize(ws.rays.size());
  selectInliers(ws.rays, ransac_pose, inlierAngle(o), ws.sample_mask);
  std::array<SE3, 2> poses;
  if (!linearGeneralizedPose(ws.rays, ws.sample_mask, poses)) return false;
  const int a = countInliers(ws.rays, poses[0], inlierAngle(o));
  const int b = countInliers(ws.rays, poses[1], inlierAngle(o));
  T = a >= b ? poses[0] : poses[1];
  return true;
}

// The struct's defaults, keeping the mask's reserved storage.
void clearResult(RelativePoseResult& result, std::size_t matches, std::size_t capacity) {
  std::vector<uint8_t> mask = std::move(result.inlier_mask);
  result = RelativePoseResult{};
  result.inlier_mask = std::move(mask);
  result.inlier_mask.assign(std::min(matches, capacity), 0);
}

}  // namespace

const char* relativePoseStatusName(RelativePoseStatus s) {
  switch (s) {
    case RelativePoseStatus::Ok: return "ok";
    case RelativePoseStatus::TooFewCorrespondences: return "too_few_correspondences";
    case RelativePoseStatus::NoConsensus: return "no_consensus";
    case RelativePoseStatus::ScaleUnobservable: return "scale_unobservable";
    case RelativePoseStatus::DirectionUnobservable: return "direction_unobservable";
    case RelativePoseStatus::LowParallax: return "low_parallax";
  }
  return "?";
}

RelativePoseEstimator::RelativePoseEstimator(int max_correspondences, int max_cameras)
    : ws_(std::make_unique<Workspace>(std::max(max_correspondences, 0), max_cameras)) {}
RelativePoseEstimator::~RelativePoseEstimator() = default;
RelativePoseEstimator::RelativePoseEstimator(RelativePoseEstimator&&) noexcept = default;
RelativePoseEstimator& RelativePoseEstimator::operator=(RelativePoseEstimator&&) noexcept = default;

const RelativePoseResult& RelativePoseEstimator::generalized(const Rig& rig,
                                                             std::span<const RelativeCorrespondence> matches,
                                                             const RelativePoseOptions& o) {
  Workspace& ws = *ws_;
  // The per-camera buffers were sized at construction: a larger rig would lose its other cameras' matches.
  if (rig.size() > static_cast<int>(ws.per_camera.size()))
    throw InputError("RelativePoseEstimator: a rig of " + std::to_string(rig.size()) + " cameras, built for at most " +
                     std::to_string(ws.per_camera.size()));
  RelativePoseResult& result = ws.result;
  clearResult(result, matches.size(), ws.capacity);
  if (rig.size() < 2) {  // one camera: no metric scale
    result.status = RelativePoseStatus::ScaleUnobservable;
    return result;
  }
  validMatches(matches, &rig, ws);
  if (static_cast<int>(ws.rays.size()) < std::max(17, o.min_inliers)) return result;

  int hypotheses = 0;
  SE3 T;
  if (generalizedRansac(ws.rays, o, ws.sample_mask, T, result.ransac_iterations)) {
    refineHypothesis(ws.rays, T, false, o, ws.scratch_mask, ws.hypotheses[hypotheses++]);
    SE3 all;
    if (allInlierHypothesis(T, o, ws, all))
      refineHypothesis(ws.rays, all, false, o, ws.scratch_mask, ws.hypotheses[hypotheses++]);
  }
  SE3 rotation_first;
  if (rotationFirstHypothesis(rig, matches, o, ws, rotation_first, result.ransac_iterations)) {
    refineHypothesis(ws.rays, rotation_first, false, o, ws.scratch_mask, ws.hypotheses[hypotheses++]);
  }
  if (hypotheses == 0) {
    result.status = RelativePoseStatus::NoConsensus;
    return result;
  }
  const Refined* best = &ws.hypotheses[0];
  for (int h = 1; h < hypotheses; ++h) best = better(ws.hypotheses[h], *best) ? &ws.hypotheses[h] : best;
  finish(ws, *best, false, o, matches.size());
  return result;
}

const RelativePoseResult& RelativePoseEstimator::central(std::span<const RelativeCorrespondence> matches,
                                                         const RelativePoseOptions& o) {
  Workspace& ws = *ws_;
  RelativePoseResult& result = ws.result;
  clearResult(result, matches.size(), ws.capacity);
  validMatches(matches, nullptr, ws);
  if (static_cast<int>(ws.rays.size()) < std::max(8, o.min_inliers)) return result;

  SE3 T;
  if (!centralRansac(ws.rays, o, T, result.ransac_iterations)) {
    result.status = RelativePoseStatus::NoConsensus;
    return result;
  }
  refineHypothesis(ws.rays, T, true, o, ws.scratch_mask, ws.hypotheses[0]);
  finish(ws, ws.hypotheses[0], true, o, matches.size());
  return result;
}

RelativePoseResult estimateGeneralizedRelativePose(const Rig& rig, std::span<const RelativeCorrespondence> matches,
                                                   const RelativePoseOptions& options) {
  RelativePoseEstimator estimator(static_cast<int>(matches.size()), rig.size());
  return estimator.generalized(rig, matches, options);
}

RelativePoseResult estimateCentralRelativePose(std::span<const RelativeCorrespondence> matches,
                                               const RelativePoseOptions& options) {
  RelativePoseEstimator estimator(static_cast<int>(matches.size()), 1);
  return estimator.central(matches, options);
}

}  // namespace mcslam
