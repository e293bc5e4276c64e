#include "mcslam/odometry/tracker.hpp"

#include <algorithm>
#include <cmath>

#include <spdlog/spdlog.h>

namespace mcslam {

namespace {

AbsolutePoseRansacOptions ransacOptions(const OdometryOptions& o) {
  AbsolutePoseRansacOptions r;
  r.min_inliers = o.min_tracked;
  r.max_iterations = 300;
  return r;
}

PoseRefinementOptions refinementOptions(const OdometryOptions& o) {
  PoseRefinementOptions r;
  r.min_inliers = o.min_tracked;
  return r;
}

}  // namespace

Tracker::Tracker(const Rig& rig, const OdometryOptions& options, int max_features_per_camera)
    : rig_(rig),
      options_(options),
      search_(rig, max_features_per_camera),
      ransac_(rig, rig.size() * max_features_per_camera, ransacOptions(options)),
      refiner_(rig, rig.size() * max_features_per_camera, refinementOptions(options)),
      tracks_(options.max_landmarks) {
  matches_.allocate(rig.size(), max_features_per_camera, options.max_landmarks);
  observations_.resize(static_cast<std::size_t>(rig.size()) * max_features_per_camera);
  observation_refs_.resize(observations_.size());
  last_tracked_.resize(options.max_landmarks);
}

void Tracker::follow(const RigState& state) {
  if (!rig_.follow(state)) return;
  for (int c = 0; c < rig_.cameras(); ++c) {
    ransac_.setExtrinsic(c, rig_.T_b_c(c));
    refiner_.setExtrinsic(c, rig_.T_b_c(c));
  }
}

bool Tracker::track(const Map& map, const FrameFeatures& frame, uint64_t frame_index, SE3& T_w_b, int& inliers) {
  const SE3 predicted = have_velocity_ ? T_w_last_ * velocity_ : T_w_last_;
  search_.prepare(frame);
  ProjectionSearchParams params;
  params.max_hamming = options_.max_hamming;
  params.ratio = options_.ratio;
  params.scale_factor = options_.scale_factor;
  params.levels = options_.levels;
  SE3 coarse;
  if (!coarsePose(map, frame, frame_index, predicted, params, coarse, inliers)) return false;

  // The local map, projected with the coarse pose into every camera, then the final refinement.
  params.radius_px = options_.local_map_radius_px;
  search_.search(map, rig_.rig(), map.liveLandmarkSlots(), map.liveLandmarkCount(), coarse, frame, params, matches_,
                 &tracks_);
  expected_matches_ = search_.predictedInImages();
  const int refined = poseFromMatches(map, frame, coarse, false, T_w_b);
  if (refined >= options_.min_tracked) {
    inliers = refined;
  } else {
    T_w_b = coarse;
  }
  most_tracked_since_keyframe_ = std::max(most_tracked_since_keyframe_, inliers);
  // Landmarks found in this frame.
  for (int c = 0; c < frame.cameras(); ++c) {
    for (int k = 0; k < frame.sets[c].count; ++k) {
      const int lm = matches_.landmarkOf(c, k);
      if (lm < 0) continue;
      LandmarkTrack& t = tracks_.of(map, lm);
      if (t.matched_frame != frame_index) {
        t.matched_frame = frame_index;
        ++t.found;
      }
    }
  }
  return true;
}

bool Tracker::coarsePose(const Map& map, const FrameFeatures& frame, uint64_t frame_index, const SE3& predicted,
                         ProjectionSearchParams& params, SE3& coarse, int& inliers) {
  // Up to three attempts of growing cost, until one is strong (a fair share of the previous frame's inliers; a
  // weak consensus is often a wrong pose after a jolt the motion model did not predict):
  //   0. the landmarks tracked in the previous frame, around the motion-model prediction;
  //   1. the whole local map with a wide radius (sudden turns, stops);
  //   2. recovery: the newest keyframe's landmarks matched by descriptor alone, any camera, no geometry.
  const auto strong = [&](int n) {
    return n >= options_.min_tracked && n >= options_.strong_tracking_share * last_coarse_inliers_;
  };
  coarse = predicted;
  int best_attempt = -1, last_attempt = -1;
  inliers = 0;
  for (int attempt = 0; attempt < 3 && !strong(inliers); ++attempt) {
    matches_.reset(frame);
    last_attempt = attempt;
    int found = 0;
    if (attempt < 2) {
      params.radius_px = options_.track_radius_px * (attempt == 0 ? 1.0 : options_.wide_radius_factor);
      const int32_t* slots = attempt == 0 ? last_tracked_.data() : map.liveLandmarkSlots();
      const int n = attempt == 0 ? last_tracked_count_ : map.liveLandmarkCount();
      found = search_.search(map, rig_.rig(), slots, n, predicted, frame, params, matches_, nullptr);
    } else {
      found = searchNewestKeyframeByDescriptor(map, frame);
    }
    SE3 candidate = predicted;
    const int held = matches_.count();  // a keypoint offered several landmarks keeps one: offers overcount
    int n = found >= options_.min_matches_for_pose ? poseFromMatches(map, frame, predicted, true, candidate) : 0;
    if (n < options_.min_consensus_share * held) n = 0;
    spdlog::trace("odometry: frame {}: coarse attempt {}: {} matches ({} offered), {} inliers", frame_index, attempt,
                  held, found, n);
    if (n > inliers) {
      inliers = n;
      coarse = candidate;
      best_attempt = attempt;
    }
  }
  if (inliers < options_.min_tracked) return false;
  if (best_attempt == 2) ++recoveries_;
  last_coarse_inliers_ = inliers;
  if (best_attempt != last_attempt) {
    // A later attempt replaced the best one's matches: find them again around the coarse pose.
    matches_.reset(frame);
    params.radius_px = options_.track_radius_px;
    search_.search(map, rig_.rig(), map.liveLandmarkSlots(), map.liveLandmarkCount(), coarse, frame, params, matches_,
                   nullptr);
  }
  return true;
}

int Tracker::searchNewestKeyframeByDescriptor(const Map& map, const FrameFeatures& frame) {
  const int newest = map.newestKeyframe();
  int n = 0;
  if (newest >= 0) {
    const Keyframe& kf = map.keyframe(newest);
    for (int c = 0; c < kf.features.cameras(); ++c) {
      for (int k = 0; k < kf.features.sets[c].count; ++k) {
        if (kf.landmark_of[c][k] >= 0) last_tracked_[n++] = kf.landmark_of[c][k];
      }
    }
  }
  last_tracked_count_ = 0;  // the list now holds keyframe landmarks, possibly repeated: not reusable
  return search_.searchByDescriptor(map, last_tracked_.data(), n, frame, options_.max_hamming, 0.8f, matches_);
}

int Tracker::poseFromMatches(const Map& map, const FrameFeatures& frame, const SE3& guess, bool use_ransac,
                             SE3& T_w_b) {
  int n = 0;
  for (int c = 0; c < frame.cameras(); ++c) {
    for (int k = 0; k < frame.sets[c].count; ++k) {
      const int lm = matches_.landmarkOf(c, k);
      if (lm < 0 || !frame.valid[c][k]) continue;
      const Keypoint& kp = frame.sets[c].keypoints[k];
      PoseObservation& o = observations_[n];
      o.camera = c;
      o.pixel = Vec2(kp.x, kp.y);
      o.ray = bodyRay(rig_.rig(), c, frame.bearings[c][k]);
      o.point_w = map.landmark(lm).p_w;
      o.sigma_px = octave_scale_[kp.octave];
      observation_refs_[n] = KeypointRef{static_cast<int16_t>(c), k};
      ++n;
    }
  }
  if (n < options_.min_matches_for_pose) return 0;
  const std::span<const PoseObservation> obs(observations_.data(), n);
  std::span<const uint8_t> mask;
  int inliers = 0;
  if (use_ransac) {
    const AbsolutePoseRansacResult r = ransac_.estimate(obs, &guess);
    if (!r.ok()) return 0;
    T_w_b = r.T_w_b;
    mask = r.inlier_mask;
    inliers = r.num_inliers;
  } else {
    const PoseRefinementResult r = refiner_.refine(obs, guess);
    if (!r.success) return 0;
    T_w_b = r.T_w_b;
    mask = r.inlier_mask;
    inliers = r.num_inliers;
  }
  for (int i = 0; i < n; ++i) {
    if (!mask[i]) matches_.clear(observation_refs_[i].cam, observation_refs_[i].index);
  }
  return inliers;
}

void Tracker::advance(const SE3& T_w_b) {
  velocity_ = T_w_last_.inverse() * T_w_b;
  have_velocity_ = true;
  rotation_travelled_ += rotationAngle(T_w_last_.R, T_w_b.R);
  T_w_last_ = T_w_b;
  moved_since_keyframe_ = true;
}

const SE3& Tracker::coast() {
  // The trajectory stays continuous through a loss.
  T_w_last_ = have_velocity_ ? T_w_last_ * velocity_ : T_w_last_;
  moved_since_keyframe_ = true;
  return T_w_last_;
}

bool Tracker::needKeyframe(const Map& map, const SE3& T_w_b, int inliers, uint64_t frame_index) const {
  // Motion since the last keyframe, as shares of the thresholds: rotation, and translation against the typical
  // depth of what is tracked.
  const SE3 motion = last_keyframe_pose_.inverse() * T_w_b;
  const double turned = so3Log(motion.R).norm() * 180.0 / M_PI / options_.keyframe_rotation_deg;
  if (turned > 1) return true;
  const double travelled = motion.t.norm() / (options_.keyframe_translation_ratio * trackedDepth(map, T_w_b));
  if (travelled > 1) return true;
  const bool interval_due = frame_index - last_keyframe_frame_ >= static_cast<uint64_t>(options_.keyframe_max_interval);
  // A map whose unit rests on its window (one camera, or a start up to scale) carries that unit from keyframe to
  // keyframe: it keeps keyframes as dense as all its keyframe's landmarks and the interval make them, standing
  // or not.
  if (unit_on_window_) return inliers < options_.keyframe_tracked_ratio * last_keyframe_landmarks_ || interval_due;
  // Against the most a frame tracked since the keyframe, not all the keyframe holds: its own new landmarks that
  // no later frame finds again (a poor match, a highlight, a passer-by) are no loss of the map.
  if (inliers < options_.keyframe_tracked_ratio * most_tracked_since_keyframe_) return true;
  // The interval keeps the window's keyframes close in time; a rig that stands still would only copy its keyframe.
  return interval_due && std::max(turned, travelled) >= options_.keyframe_still_share;
}

double Tracker::trackedDepth(const Map& map, const SE3& T_w_b) const {
  double depth_sum = 0;
  int depth_n = 0;
  for (int i = 0; i < last_tracked_count_ && depth_n < 200; ++i) {
    depth_sum += (map.landmark(last_tracked_[i]).p_w - T_w_b.t).norm();
    ++depth_n;
  }
  return depth_n ? depth_sum / depth_n : 1.0;
}

int Tracker::countKeyframeLandmarks(const Map& map, int slot) const {
  const Keyframe& kf = map.keyframe(slot);
  int n = 0;
  for (int c = 0; c < kf.features.cameras(); ++c) {
    for (int k = 0; k < kf.features.sets[c].count; ++k) n += kf.landmark_of[c][k] >= 0 ? 1 : 0;
  }
  return n;
}

void Tracker::keyframeSettled(const Map& map, int slot) {
  const SE3& settled = map.keyframe(slot).T_w_b;
  // Frames tracked since the keyframe were tracked against the map before its solve: they move with the keyframe.
  T_w_last_ = moved_since_keyframe_ ? settled * last_keyframe_pose_.inverse() * T_w_last_ : settled;
  last_keyframe_pose_ = settled;
  last_keyframe_landmarks_ = countKeyframeLandmarks(map, slot);
  int kept = 0;
  for (int i = 0; i < last_tracked_count_; ++i) {
    if (map.landmark(last_tracked_[i]).alive) last_tracked_[kept++] = last_tracked_[i];
  }
  last_tracked_count_ = kept;
}

void Tracker::rememberTracked(const Map& map, const FrameFeatures& frame, uint64_t frame_index) {
  last_tracked_count_ = 0;
  for (int c = 0; c < frame.cameras(); ++c) {
    for (int k = 0; k < frame.sets[c].count; ++k) {
      const int lm = matches_.landmarkOf(c, k);
      if (lm < 0 || !map.landmark(lm).alive) continue;
      LandmarkTrack& t = tracks_.of(map, lm);
      if (t.listed_frame == frame_index) continue;  // a landmark seen by several cameras: once
      t.listed_frame = frame_index;
      last_tracked_[last_tracked_count_++] = lm;
    }
  }
}

void Tracker::startFrom(const Map& map, int slot, uint64_t frame_index, bool unit_on_window) {
  unit_on_window_ = unit_on_window;
  T_w_last_ = map.keyframe(slot).T_w_b;
  moved_since_keyframe_ = false;
  have_velocity_ = false;
  last_keyframe_frame_ = frame_index;
  last_keyframe_pose_ = T_w_last_;
  most_tracked_since_keyframe_ = 0;
  last_tracked_count_ = 0;
  // The frame the map starts on saw every landmark of its keyframe: the next one, tracked with no motion model
  // yet, must find a fair share of them before its first attempt is trusted (after a relocalization in a turn,
  // the stale prediction finds a chance consensus of repeated texture).
  last_keyframe_landmarks_ = countKeyframeLandmarks(map, slot);
  last_coarse_inliers_ = last_keyframe_landmarks_;
  const Keyframe& kf = map.keyframe(slot);
  for (int c = 0; c < kf.features.cameras(); ++c) {
    for (int k = 0; k < kf.features.sets[c].count; ++k) {
      const int lm = kf.landmark_of[c][k];
      if (lm < 0) continue;
      LandmarkTrack& t = tracks_.of(map, lm);
      if (t.matched_frame != frame_index) {
        t.matched_frame = frame_index;
        last_tracked_[last_tracked_count_++] = lm;
      }
    }
  }
}

void Tracker::reset() {
  last_tracked_count_ = 0;
  last_coarse_inliers_ = 0;
  have_velocity_ = false;
}

void Tracker::rescale(double s, const Vec3& center) {
  T_w_last_.t = center + s * (T_w_last_.t - center);
  last_keyframe_pose_.t = center + s * (last_keyframe_pose_.t - center);
  velocity_.t *= s;
}

float Tracker::quality(int inliers) const {
  return static_cast<float>(std::min(1.0, inliers / std::max(1.0, static_cast<double>(expected_matches_))));
}

}  // namespace mcslam
