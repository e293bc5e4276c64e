#include "mcslam/odometry/local_mapper.hpp"

#include <algorithm>

#include "mcslam/odometry/window_bridge.hpp"

namespace mcslam {

LocalMapper::LocalMapper(const OdometryOptions& options)
    : options_(options), touched_(options.max_landmarks), touched_flag_(options.max_landmarks, 0) {}

void LocalMapper::reset() {
  std::fill(touched_flag_.begin(), touched_flag_.end(), 0);
  touched_count_ = 0;
}

void LocalMapper::touch(int lm) {
  if (touched_flag_[lm]) return;
  touched_flag_[lm] = 1;
  touched_[touched_count_++] = lm;
}

void LocalMapper::finishTouched(Map& map, const Rig& rig) {
  for (int i = 0; i < touched_count_; ++i) {
    const int lm = touched_[i];
    touched_flag_[lm] = 0;
    if (map.landmark(lm).alive) map.updateLandmarkAppearance(lm, rig, options_.scale_factor, options_.levels);
  }
  touched_count_ = 0;
}

int LocalMapper::allocateKeyframe(Map& map, WindowBridge& bridge) {
  int slot = map.createKeyframe();
  if (slot >= 0) return slot;
  // The pool is full: drop the oldest keyframe that has left the back-end window.
  int victim = -1;
  for (int i = 0; i < map.keyframeCapacity(); ++i) {
    const Keyframe& k = map.keyframe(i);
    if (k.alive && !k.in_backend && (victim < 0 || k.id < map.keyframe(victim).id)) victim = i;
  }
  if (victim < 0) return -1;
  // Its landmarks lose their observations there; those left with none die, and leave the back-end first.
  const Keyframe& v = map.keyframe(victim);
  for (int c = 0; c < v.features.cameras(); ++c) {
    for (int k = 0; k < v.features.sets[c].count; ++k) {
      const int lm = v.landmark_of[c][k];
      if (lm < 0) continue;
      const Landmark& l = map.landmark(lm);
      bool elsewhere = false;
      for (int o = 0; o < l.obs_count && !elsewhere; ++o) elsewhere = l.obs[o].keyframe != victim;
      if (!elsewhere) bridge.removeLandmark(map, lm);
    }
  }
  map.eraseKeyframe(victim);
  return map.createKeyframe();
}

int LocalMapper::startKeyframe(Map& map, WindowBridge& bridge, const FrameFeatures& frame, const SE3& T_w_b,
                               uint64_t frame_index) {
  const int slot = allocateKeyframe(map, bridge);
  if (slot < 0) return -1;
  Keyframe& kf = map.keyframe(slot);
  kf.features = frame;
  kf.T_w_b = T_w_b;
  kf.t = frame.t;
  kf.frame_index = frame_index;
  return slot;
}

int LocalMapper::insertKeyframe(Map& map, WindowBridge& bridge, const Rig& rig, const FrameFeatures& frame,
                                const FrameMatches* matches, const SE3& T_w_b, uint64_t frame_index,
                                bool create_multiview_points) {
  const int slot = startKeyframe(map, bridge, frame, T_w_b, frame_index);
  if (slot < 0) return -1;
  if (matches) {
    for (int c = 0; c < frame.cameras(); ++c) {
      for (int k = 0; k < frame.sets[c].count; ++k) {
        const int lm = matches->landmarkOf(c, k);
        if (lm >= 0 && map.landmark(lm).alive && map.addObservation(lm, slot, c, k)) touch(lm);
      }
    }
    linkMultiViewPartners(map, rig, slot, frame);
  }
  if (create_multiview_points) createMultiViewLandmarks(map, slot, frame);
  finishTouched(map, rig);
  return slot;
}

int LocalMapper::insertSeededKeyframe(Map& map, WindowBridge& bridge, const Rig& rig, const FrameFeatures& frame,
                                      std::span<const MapSeed> seeds, const SE3& T_w_b, uint64_t frame_index) {
  const int slot = startKeyframe(map, bridge, frame, T_w_b, frame_index);
  if (slot < 0) return -1;
  const int64_t kf_id = map.keyframe(slot).id;
  for (const MapSeed& seed : seeds) {
    if (map.keyframe(slot).landmark_of[seed.cam][seed.kp] >= 0) continue;  // two seeds on one keypoint
    const int lm = map.createLandmark(seed.p_w, seed.descriptor, kf_id);
    if (lm < 0) break;
    map.landmark(lm).metric = seed.metric;
    map.addObservation(lm, slot, seed.cam, seed.kp);
    touch(lm);
  }
  linkMultiViewPartners(map, rig, slot, frame);
  createMultiViewLandmarks(map, slot, frame);
  finishTouched(map, rig);
  return slot;
}

void LocalMapper::createMultiViewLandmarks(Map& map, int slot, const FrameFeatures& frame) {
  Keyframe& kf = map.keyframe(slot);
  for (int t = 0; t < frame.mv_count; ++t) {
    const MultiViewFeature& mv = frame.mv[t];
    if (!mv.has_point || mv.relative_depth_sigma > options_.landmark_max_depth_sigma) continue;
    bool linked = false;
    for (int r = 0; r < mv.size && !linked; ++r) {
      const KeypointRef& ref = frame.mv_refs[mv.first + r];
      linked = kf.landmark_of[ref.cam][ref.index] >= 0;
    }
    if (linked) continue;
    const int lm = map.createLandmark(kf.T_w_b * mv.p_b, mv.descriptor, kf.id);
    if (lm < 0) break;  // map full: keep tracking with what we have
    map.landmark(lm).metric = true;
    for (int r = 0; r < mv.size; ++r) {
      const KeypointRef& ref = frame.mv_refs[mv.first + r];
      map.addObservation(lm, slot, ref.cam, ref.index);
    }
    touch(lm);
  }
}

// Keypoints of one multi-view feature see the same point: when one of them was matched to a landmark,
// the others observe it too if it projects onto them.
void LocalMapper::linkMultiViewPartners(Map& map, const Rig& rig, int slot, const FrameFeatures& frame) {
  Keyframe& kf = map.keyframe(slot);
  for (int t = 0; t < frame.mv_count; ++t) {
    const MultiViewFeature& mv = frame.mv[t];
    int lm = -1;
    for (int r = 0; r < mv.size && lm < 0; ++r) {
      const KeypointRef& ref = frame.mv_refs[mv.first + r];
      lm = kf.landmark_of[ref.cam][ref.index];
    }
    if (lm < 0) continue;
    const Landmark& l = map.landmark(lm);
    for (int r = 0; r < mv.size; ++r) {
      const KeypointRef& ref = frame.mv_refs[mv.first + r];
      if (kf.landmark_of[ref.cam][ref.index] >= 0) continue;
      const Keypoint& kp = frame.sets[ref.cam].keypoints[ref.index];
      Vec2 uv;
      const Vec3 p_c = (kf.T_w_b * rig.T_b_c(ref.cam)).inverse() * l.p_w;
      if (!rig.model(ref.cam).project(p_c, uv)) continue;
      const double e = (uv - Vec2(kp.x, kp.y)).norm() / octave_scale_[kp.octave];
      if (e * e < 5.991 && map.addObservation(lm, slot, ref.cam, ref.index)) touch(lm);
    }
  }
}

void LocalMapper::updateAppearance(Map& map, const Rig& rig, std::span<const int32_t> landmarks, bool now) {
  for (const int32_t lm : landmarks) touch(lm);
  if (now) finishTouched(map, rig);
}

int LocalMapper::cull(Map& map, WindowBridge& bridge, int newest_slot, const LandmarkTracks& tracks) {
  const int64_t newest_id = map.keyframe(newest_slot).id;
  map.refreshLiveList();
  int erased = 0;
  for (int i = 0; i < map.liveLandmarkCount(); ++i) {
    const int lm = map.liveLandmarkSlots()[i];
    const Landmark& l = map.landmark(lm);
    if (!l.alive) continue;
    const LandmarkTrack& t = tracks.peek(map, lm);
    const bool rarely_found = t.visible >= static_cast<uint32_t>(options_.cull_min_visible) &&
                              t.found < options_.cull_min_found_ratio * t.visible;
    const bool never_confirmed = !l.metric && l.created_keyframe_id <= newest_id - 3 && map.observingKeyframes(lm) < 2;
    if (l.obs_count == 0 || rarely_found || never_confirmed) {
      bridge.removeLandmark(map, lm);
      map.eraseLandmark(lm);
      ++erased;
    }
  }
  return erased;
}

}  // namespace mcslam
