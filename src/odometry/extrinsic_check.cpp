#include "extrinsic_check.hpp"
#include "mcslam/core/median.hpp"

#include <algorithm>
#include <cmath>

#include <spdlog/spdlog.h>

namespace mcslam {

namespace {

// A camera is suspect when it holds fewer than this share of the inliers the other cameras hold (median):
// a camera whose extrinsic is within the gate keeps a share of the same order as its neighbours'.
constexpr double kCollapsedShare = 0.25;

}  // namespace

ExtrinsicCheck::ExtrinsicCheck(const Rig& rig, const OdometryOptions& options, int max_features_per_camera)
    : options_(options), gate_px_(std::sqrt(AbsolutePoseRansacOptions{}.chi2_threshold)) {
  const int cams = rig.size();
  AbsolutePoseRansacOptions ro;
  // A lone camera fixes six degrees of freedom from its own points: twice the rig's minimum.
  ro.min_inliers = 2 * options.min_tracked;
  ro.max_iterations = 300;
  for (int c = 0; c < cams; ++c) {
    Rig alone;
    alone.cameras.push_back(rig.cameras[c]);
    alone.cameras[0].T_b_c = SE3();  // its "body" is the camera
    ransac_.push_back(std::make_unique<AbsolutePoseRansac>(alone, max_features_per_camera, ro));
  }
  wide_.allocate(cams, max_features_per_camera, options.max_landmarks);
  obs_.resize(max_features_per_camera);
  scratch_.resize(std::max(max_features_per_camera, kSamples));
  inliers_.resize(cams);
  samples_.assign(cams, std::vector<Sample>(kSamples));
  sample_count_.assign(cams, 0);
}

ExtrinsicCheck::~ExtrinsicCheck() = default;

void ExtrinsicCheck::reset() { std::fill(sample_count_.begin(), sample_count_.end(), 0); }

int ExtrinsicCheck::check(const Map& map, ProjectionSearch& search, const Rig& rig, const FrameFeatures& frame,
                          const FrameMatches& matches, const SE3& T_w_b, SE3& T_b_c) {
  const int cam = suspectCamera(frame, matches);
  if (cam < 0) return -1;
  Sample s;
  if (!sample(cam, map, search, rig, frame, T_w_b, s)) return -1;
  // The newest kSamples, oldest overwritten. They are absolute extrinsics: the back-end's small moves of the
  // estimate between frames do not invalidate them.
  samples_[cam][sample_count_[cam] % kSamples] = s;
  ++sample_count_[cam];
  return decide(cam, rig, T_b_c) ? cam : -1;
}

int ExtrinsicCheck::suspectCamera(const FrameFeatures& frame, const FrameMatches& matches) {
  const int cams = frame.cameras();
  for (int c = 0; c < cams; ++c) {
    int n = 0;
    for (int k = 0; k < frame.sets[c].count; ++k) n += matches.landmarkOf(c, k) >= 0 ? 1 : 0;
    inliers_[c] = n;
  }
  int suspect = -1;
  double lowest = kCollapsedShare;
  // Camera 0 is never suspect: the back-end holds its extrinsic fixed, it defines the body frame.
  for (int c = 1; c < cams; ++c) {
    if (!frame.present[c]) continue;
    int n = 0;
    for (int o = 0; o < cams; ++o) {
      if (o != c && frame.present[o]) scratch_[n++] = inliers_[o];
    }
    if (n == 0) continue;
    const double others = medianOf(scratch_, n);
    if (others < 2 * options_.min_tracked) continue;  // the others track too little to compare with
    const double share = inliers_[c] / others;
    if (share < lowest) {
      lowest = share;
      suspect = c;
    }
  }
  return suspect;
}

bool ExtrinsicCheck::sample(int cam, const Map& map, ProjectionSearch& search, const Rig& rig,
                            const FrameFeatures& frame, const SE3& T_w_b, Sample& out) {
  // The local map into this camera alone, with the tracking's wide window (its second attempt's radius).
  ProjectionSearchParams p;
  p.max_hamming = options_.max_hamming;
  p.ratio = options_.ratio;
  p.scale_factor = options_.scale_factor;
  p.levels = options_.levels;
  p.radius_px = options_.track_radius_px * options_.wide_radius_factor;
  p.camera = cam;
  wide_.reset(frame);
  search.search(map, rig, map.liveLandmarkSlots(), map.liveLandmarkCount(), T_w_b, frame, p, wide_, nullptr);
  int n = 0;
  for (int k = 0; k < frame.sets[cam].count; ++k) {
    const int lm = wide_.landmarkOf(cam, k);
    if (lm < 0 || !frame.valid[cam][k]) continue;
    const Keypoint& kp = frame.sets[cam].keypoints[k];
    PoseObservation& o = obs_[n++];
    o.camera = 0;
    o.pixel = Vec2(kp.x, kp.y);
    o.ray = BodyRay{Vec3::Zero(), frame.bearings[cam][k]};
    o.point_w = map.landmark(lm).p_w;
    o.sigma_px = octave_scale_[kp.octave];
  }
  AbsolutePoseRansac& ransac = *ransac_[cam];
  if (n < ransac.options().min_inliers) return false;
  const SE3 predicted = T_w_b * rig.T_b_c(cam);
  const AbsolutePoseRansacResult r = ransac.estimate(std::span<const PoseObservation>(obs_.data(), n), &predicted);
  if (!r.ok()) return false;
  const SE3 T_c_w = r.T_w_b.inverse();
  int m = 0;
  for (int i = 0; i < n; ++i) {
    if (r.inlier_mask[i]) scratch_[m++] = (T_c_w * obs_[i].point_w).norm();
  }
  out.T_b_c = T_w_b.inverse() * r.T_w_b;
  out.depth = medianOf(scratch_, m);
  return true;
}

bool ExtrinsicCheck::decide(int cam, const Rig& rig, SE3& T_b_c) {
  if (sample_count_[cam] < kSamples) return false;
  const std::vector<Sample>& s = samples_[cam];
  const SE3& current = rig.T_b_c(cam);
  // Component-wise median in the tangent space at the current estimate (robust to a wrong frame or two).
  Vec6 median;
  for (int j = 0; j < 6; ++j) {
    for (int i = 0; i < kSamples; ++i) {
      scratch_[i] = j < 3 ? (current.R.transpose() * (s[i].T_b_c.t - current.t))[j]
                          : so3Log(current.R.transpose() * s[i].T_b_c.R)[j - 3];
    }
    median[j] = medianOf(scratch_, kSamples);
  }
  for (int i = 0; i < kSamples; ++i) scratch_[i] = s[i].depth;
  const double depth = medianOf(scratch_, kSamples);
  // A lone camera's translation shows only through parallax: a change that moves its points by less than the
  // gate at their median depth is not resolved by these frames (it trades off against the rotation), so the
  // current translation is kept and the back-end refines it once the points pass the gate again.
  const CameraModel& model = rig.model(cam);
  const double f = 0.5 * (model.fx() + model.fy());
  const bool translation_resolved = f * median.head<3>().norm() / depth > gate_px_;
  const SE3 full(current.R * so3Exp(median.tail<3>()), current.t + current.R * median.head<3>());
  const SE3 candidate(full.R, translation_resolved ? full.t : current.t);
  // The frames must agree: half of them within the inlier gate of their median. Then the candidate, known to
  // about gate / sqrt(kSamples), puts the camera's points back inside the gate.
  for (int i = 0; i < kSamples; ++i) scratch_[i] = pixelShift(model, full, s[i].T_b_c, depth);
  const double spread = medianOf(scratch_, kSamples);
  if (!(spread < gate_px_)) return false;
  // And the correction must matter: it moves the camera's points by more than the gate (less, and the
  // back-end sees enough of them to refine the extrinsic on its own).
  const double shift = pixelShift(model, current, candidate, depth);
  if (!(shift > gate_px_)) return false;
  const SE3 change = current.inverse() * candidate;
  spdlog::info(
      "odometry: camera {} extrinsic re-estimated from {} frames: moved {:.1f} mm, {:.2f} deg "
      "({:.1f} px at {:.1f} m; the frames agree to {:.2f} px)",
      cam, kSamples, change.t.norm() * 1e3, so3Log(change.R).norm() * 180.0 / M_PI, shift, depth, spread);
  T_b_c = candidate;
  sample_count_[cam] = 0;
  return true;
}

double ExtrinsicCheck::pixelShift(const CameraModel& model, const SE3& a, const SE3& b, double depth) const {
  const SE3 T_b_a = b.inverse() * a;
  const double w = model.width(), h = model.height();
  const Vec2 probes[5] = {
      {0.5 * w, 0.5 * h}, {0.25 * w, 0.25 * h}, {0.75 * w, 0.25 * h}, {0.25 * w, 0.75 * h}, {0.75 * w, 0.75 * h}};
  double sum = 0;
  for (const Vec2& uv : probes) {
    Vec3 bearing;
    Vec2 moved;
    if (!model.unproject(uv, bearing) || !model.project(T_b_a * (depth * bearing), moved)) return INFINITY;
    sum += (moved - uv).squaredNorm();
  }
  return std::sqrt(sum / 5.0);
}

}  // namespace mcslam
