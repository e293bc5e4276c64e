#include "mcslam/geometry/relative_pose.hpp"

#include <algorithm>
#include <climits>
#include <memory>
#include <opengv/relative_pose/CentralRelativeAdapter.hpp>
#include <opengv/relative_pose/NoncentralRelativeAdapter.hpp>
#include <opengv/relative_pose/methods.hpp>
#include <opengv/sac/Ransac.hpp>
#include <opengv/sac_problems/relative_pose/CentralRelativePoseSacProblem.hpp>
#include <opengv/sac_problems/relative_pose/NoncentralRelativePoseSacProblem.hpp>

#include "mcslam/geometry/ransac.hpp"
#include "mcslam/geometry/relative_pose_refinement.hpp"

namespace mcslam {

using namespace relative_pose_detail;

namespace {

// OpenGV's problems seed their generator from the clock or with a constant; ours draws the samples
// from our seeded generator instead, so the caller's seed decides.
template <class Problem>
class SeededProblem : public Problem {
 public:
  template <class... Args>
  explicit SeededProblem(uint64_t seed, Args&&... args) : Problem(std::forward<Args>(args)...), random_(seed) {}

  void getSamples(int& iterations, std::vector<int>& samples) override {
    const std::vector<int>& indices = *this->getIndices();
    const int k = this->getSampleSize();
    const int n = static_cast<int>(indices.size());
    if (n < k) {
      samples.clear();
      iterations = INT_MAX;
      return;
    }
    samples.resize(k);
    random_.distinct(n, k, samples.data());
    for (int& s : samples) s = indices[s];
  }

 private:
  RansacRandom random_;
};

struct Valid {
  std::vector<int> index;  // into the caller's matches
  std::vector<RayPair> rays;
};

// Correspondences with finite bearings and cameras of the rig (all of them when rig is null),
// normalized, as rays in the frames the pose is solved in.
Valid validMatches(std::span<const RelativeCorrespondence> matches, const Rig* rig) {
  Valid v;
  for (size_t i = 0; i < matches.size(); ++i) {
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
    v.index.push_back(static_cast<int>(i));
    v.rays.push_back(r);
  }
  return v;
}

// Inlier threshold on our (Sampson) angle error.
double inlierAngle(const RelativePoseOptions& o) { return o.inlier_sigmas * o.bearing_sigma_rad; }
// The threshold of OpenGV's relative problems: the sum over both views of (1 - cos) of the
// reprojection angle, for the same number of sigmas in each view.
double openGvThreshold(const RelativePoseOptions& o) { return 2.0 * (1.0 - std::cos(inlierAngle(o))); }

struct Refined {
  SE3 T;
  std::vector<uint8_t> mask;
  int inliers = 0;
  double cost = INFINITY;  // sum of squared errors over the inliers
};

// Our refinement of one hypothesis: select inliers, refine, re-select (the set settles quickly).
// Generalized poses are refined at fixed scale first, then freely; the free step is kept only if
// it loses no inliers (where the scale is weak it slides toward t = 0 and points flip behind).
Refined refineHypothesis(const Valid& v, const SE3& start, bool central, const RelativePoseOptions& o) {
  Refined r;
  r.T = start;
  if (central) r.T.t.normalize();
  selectInliers(v.rays, r.T, inlierAngle(o), r.mask);
  std::vector<uint8_t> free_mask;
  for (int round = 0; round < 3; ++round) {
    r.T = refineRelativePose(v.rays, r.mask, r.T, true, o);
    r.inliers = selectInliers(v.rays, r.T, inlierAngle(o), r.mask);
    if (central) continue;
    const SE3 free = refineRelativePose(v.rays, r.mask, r.T, false, o);
    const int free_inliers = selectInliers(v.rays, free, inlierAngle(o), free_mask);
    if (free_inliers >= r.inliers) {
      r.T = free;
      r.inliers = free_inliers;
      r.mask.swap(free_mask);
    }
  }
  r.cost = 0;
  for (size_t i = 0; i < v.rays.size(); ++i) {
    if (r.mask[i]) r.cost += std::pow(sampsonError(v.rays[i], r.T), 2);
  }
  return r;
}

bool better(const Refined& a, const Refined& b) {
  return a.inliers > b.inliers || (a.inliers == b.inliers && a.cost < b.cost);
}

// Inliers, observability and status of the chosen pose, shared by both cases.
void finish(const Valid& v, const Refined& best, bool central, const RelativePoseOptions& o, size_t num_matches,
            RelativePoseResult& result) {
  result.T_1_2 = best.T;
  result.metric = !central;
  result.inlier_mask.assign(num_matches, 0);
  result.num_inliers = best.inliers;
  for (size_t i = 0; i < best.mask.size(); ++i) result.inlier_mask[v.index[i]] = best.mask[i];
  if (result.num_inliers < o.min_inliers) {
    result.status = RelativePoseStatus::NoConsensus;
    return;
  }
  const Observability obs = analyzeObservability(v.rays, best.mask, best.T, central, o.bearing_sigma_rad);
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

// 5-point RANSAC on central rays; returns false without consensus.
bool centralRansac(const std::vector<RayPair>& rays, const RelativePoseOptions& o, SE3& T, int& iterations) {
  opengv::bearingVectors_t b1, b2;
  for (const RayPair& r : rays) {
    b1.push_back(r.d1);
    b2.push_back(r.d2);
  }
  opengv::relative_pose::CentralRelativeAdapter adapter(b1, b2);
  using Problem = opengv::sac_problems::relative_pose::CentralRelativePoseSacProblem;
  opengv::sac::Ransac<SeededProblem<Problem>> ransac;
  ransac.sac_model_ = std::make_shared<SeededProblem<Problem>>(o.seed, adapter, Problem::NISTER, false);
  ransac.threshold_ = openGvThreshold(o);
  ransac.max_iterations_ = o.max_iterations;
  ransac.probability_ = o.confidence;
  const bool found = ransac.computeModel();
  iterations += ransac.iterations_;
  if (!found || static_cast<int>(ransac.inliers_.size()) < std::max(8, o.min_inliers / 4)) return false;
  const opengv::transformation_t& M = ransac.model_coefficients_;
  T = SE3(M.leftCols<3>(), M.col(3).normalized());
  return true;
}

// Rotation-first hypothesis for rigs whose matches stay within cameras (where the 17-point solver
// is weakest: little rotation, non-overlapping cameras): the camera with the most matches gives
// the rotation and the direction of its own motion by the 5-point solver; the metric scale along
// that direction is then the value most matches of all cameras agree with.
bool rotationFirstHypothesis(const Rig& rig, std::span<const RelativeCorrespondence> matches, const Valid& v,
                             const RelativePoseOptions& o, SE3& T, int& iterations) {
  std::vector<int> count(rig.size(), 0);
  for (int i : v.index) {
    if (matches[i].camera1 == matches[i].camera2) ++count[matches[i].camera1];
  }
  const int cam = static_cast<int>(std::max_element(count.begin(), count.end()) - count.begin());
  if (count[cam] < 16) return false;
  Valid own;
  for (size_t k = 0; k < v.index.size(); ++k) {
    const RelativeCorrespondence& m = matches[v.index[k]];
    if (m.camera1 != cam || m.camera2 != cam) continue;
    own.index.push_back(static_cast<int>(k));
    own.rays.push_back({Vec3::Zero(), m.bearing1.normalized(), Vec3::Zero(), m.bearing2.normalized()});
  }
  SE3 T_c;
  if (!centralRansac(own.rays, o, T_c, iterations)) return false;
  T_c = refineHypothesis(own, T_c, true, o).T;

  // Body motion as a function of the camera's unknown scale s: t(s) = t0 + s * dir.
  const SE3& T_b_c = rig.T_b_c(cam);
  const Mat3 R = T_b_c.R * T_c.R * T_b_c.R.transpose();
  const Vec3 dir = T_b_c.R * T_c.t;
  const Vec3 t0 = T_b_c.t - R * T_b_c.t;
  // Each match's error is linear in s: e = alpha s + beta; its root is a candidate scale.
  // The camera moved along +dir (the 5-point solution is in front of the camera), so s > 0. When
  // nothing fixes s (no rotation) any value fits: s = 1 is then as good as another and the
  // observability check reports it.
  std::vector<double> candidates{1.0};
  for (const RayPair& p : v.rays) {
    const double beta = sampsonError(p, SE3(R, t0));
    const double alpha = sampsonError(p, SE3(R, t0 + dir)) - beta;  // e is affine in t (normalization frozen)
    if (std::abs(alpha) > 1e-12 && -beta / alpha > 0) candidates.push_back(-beta / alpha);
  }
  RansacRandom random(o.seed);
  int best_inliers = -1;
  double best_s = 1.0;
  std::vector<uint8_t> mask;
  const int tries = std::min<int>(static_cast<int>(candidates.size()), 300);
  for (int k = 0; k < tries; ++k) {
    const double s =
        candidates.size() <= 300 ? candidates[k] : candidates[random.below(static_cast<int>(candidates.size()))];
    const int inl = selectInliers(v.rays, SE3(R, t0 + s * dir), inlierAngle(o), mask);
    if (inl > best_inliers) {
      best_inliers = inl;
      best_s = s;
    }
  }
  T = SE3(R, t0 + best_s * dir);
  return true;
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

RelativePoseResult estimateGeneralizedRelativePose(const Rig& rig, std::span<const RelativeCorrespondence> matches,
                                                   const RelativePoseOptions& o) {
  RelativePoseResult result;
  result.inlier_mask.assign(matches.size(), 0);
  if (rig.size() < 2) {  // one camera: no metric scale
    result.status = RelativePoseStatus::ScaleUnobservable;
    return result;
  }
  const Valid v = validMatches(matches, &rig);
  if (static_cast<int>(v.rays.size()) < std::max(17, o.min_inliers)) return result;

  // OpenGV wants camera-frame bearings and the rig's extrinsics.
  opengv::bearingVectors_t b1, b2;
  std::vector<int> cam1, cam2;
  for (int i : v.index) {
    b1.push_back(matches[i].bearing1.normalized());
    b2.push_back(matches[i].bearing2.normalized());
    cam1.push_back(matches[i].camera1);
    cam2.push_back(matches[i].camera2);
  }
  opengv::translations_t offsets;
  opengv::rotations_t rotations;
  for (const RigCamera& c : rig.cameras) {
    offsets.push_back(c.T_b_c.t);
    rotations.push_back(c.T_b_c.R);
  }
  opengv::relative_pose::NoncentralRelativeAdapter adapter(b1, b2, cam1, cam2, offsets, rotations);
  using Problem = opengv::sac_problems::relative_pose::NoncentralRelativePoseSacProblem;
  opengv::sac::Ransac<SeededProblem<Problem>> ransac;
  ransac.sac_model_ = std::make_shared<SeededProblem<Problem>>(o.seed, adapter, Problem::SEVENTEENPT, false, false);
  ransac.threshold_ = openGvThreshold(o);
  ransac.max_iterations_ = o.max_iterations;
  ransac.probability_ = o.confidence;
  std::vector<Refined> refined;
  if (ransac.computeModel() && static_cast<int>(ransac.inliers_.size()) >= 17) {
    const opengv::transformation_t& M = ransac.model_coefficients_;
    refined.push_back(refineHypothesis(v, SE3(M.leftCols<3>(), M.col(3)), false, o));
    // The linear solver on all its inliers is far less noisy than on 17 points.
    const opengv::transformation_t all = opengv::relative_pose::seventeenpt(adapter, ransac.inliers_);
    refined.push_back(refineHypothesis(v, SE3(all.leftCols<3>(), all.col(3)), false, o));
  }
  result.ransac_iterations = ransac.iterations_;
  SE3 rotation_first;
  if (rotationFirstHypothesis(rig, matches, v, o, rotation_first, result.ransac_iterations)) {
    refined.push_back(refineHypothesis(v, rotation_first, false, o));
  }
  if (refined.empty()) {
    result.status = RelativePoseStatus::NoConsensus;
    return result;
  }
  const Refined* best = &refined[0];
  for (const Refined& r : refined) best = better(r, *best) ? &r : best;
  finish(v, *best, false, o, matches.size(), result);
  return result;
}

RelativePoseResult estimateCentralRelativePose(std::span<const RelativeCorrespondence> matches,
                                               const RelativePoseOptions& o) {
  RelativePoseResult result;
  result.inlier_mask.assign(matches.size(), 0);
  const Valid v = validMatches(matches, nullptr);
  if (static_cast<int>(v.rays.size()) < std::max(8, o.min_inliers)) return result;

  SE3 T;
  if (!centralRansac(v.rays, o, T, result.ransac_iterations)) {
    result.status = RelativePoseStatus::NoConsensus;
    return result;
  }
  finish(v, refineHypothesis(v, T, true, o), true, o, matches.size(), result);
  return result;
}

}  // namespace mcslam
