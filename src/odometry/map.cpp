#include "mcslam/odometry/map.hpp"

#include <algorithm>
#include <cmath>

namespace mcslam {

Map::Map(const Rig& rig, int max_features_per_camera, int max_keyframes, int max_landmarks)
    : landmarks_(max_landmarks),
      free_landmarks_(max_landmarks),
      live_list_(max_landmarks),
      keyframes_(max_keyframes),
      medoid_scratch_(kMaxLandmarkObservations) {
  size_t n = 16;
  while (n < static_cast<size_t>(max_landmarks) * 2) n <<= 1;  // load factor at most 1/2
  id_keys_.assign(n, -1);
  id_slots_.assign(n, -1);
  id_mask_ = n - 1;
  const int cameras = rig.size();
  for (Keyframe& kf : keyframes_) {
    kf.features.allocate(cameras, max_features_per_camera);
    kf.landmark_of.assign(cameras, std::vector<int32_t>(max_features_per_camera, -1));
  }
  clear();
}

void Map::clear() {
  for (Landmark& l : landmarks_) l.alive = false;
  std::fill(id_slots_.begin(), id_slots_.end(), -1);
  for (Keyframe& k : keyframes_) k.alive = false;
  free_landmark_count_ = static_cast<int>(landmarks_.size());
  for (int i = 0; i < free_landmark_count_; ++i) free_landmarks_[i] = free_landmark_count_ - 1 - i;
  live_landmarks_ = 0;
  live_list_count_ = 0;
  live_list_dirty_ = false;
}

int Map::createLandmark(const Vec3& p_w, const Descriptor& d, int64_t keyframe_id) {
  if (free_landmark_count_ == 0) return -1;
  const int slot = free_landmarks_[--free_landmark_count_];
  Landmark& l = landmarks_[slot];
  l = Landmark{};
  l.alive = true;
  l.id = next_landmark_id_++;
  indexId(l.id, slot);
  l.p_w = p_w;
  l.descriptor = d;
  l.created_keyframe_id = keyframe_id;
  ++live_landmarks_;
  live_list_dirty_ = true;
  return slot;
}

void Map::eraseLandmark(int slot) {
  Landmark& l = landmarks_[slot];
  if (!l.alive) return;
  for (int o = 0; o < l.obs_count; ++o) {
    Keyframe& kf = keyframes_[l.obs[o].keyframe];
    if (kf.alive && kf.landmark_of[l.obs[o].cam][l.obs[o].kp] == slot) kf.landmark_of[l.obs[o].cam][l.obs[o].kp] = -1;
  }
  l.alive = false;
  l.obs_count = 0;
  unindexId(l.id);
  free_landmarks_[free_landmark_count_++] = slot;
  --live_landmarks_;
  live_list_dirty_ = true;
}

size_t Map::idHome(int64_t id) const {
  const uint64_t x = static_cast<uint64_t>(id) * 0x9E3779B97F4A7C15ull;  // Fibonacci hashing
  return (x ^ (x >> 29)) & id_mask_;
}

int Map::landmarkSlotOf(int64_t id) const {
  for (size_t i = idHome(id);; i = (i + 1) & id_mask_) {
    if (id_slots_[i] < 0) return -1;
    if (id_keys_[i] == id) return id_slots_[i];
  }
}

void Map::indexId(int64_t id, int slot) {
  size_t i = idHome(id);
  while (id_slots_[i] >= 0) i = (i + 1) & id_mask_;
  id_keys_[i] = id;
  id_slots_[i] = slot;
}

void Map::unindexId(int64_t id) {
  size_t i = idHome(id);
  for (;; i = (i + 1) & id_mask_) {
    if (id_slots_[i] < 0) return;
    if (id_keys_[i] == id) break;
  }
  // Entries after the hole whose probe path crosses it move back into it.
  size_t hole = i;
  for (size_t j = (i + 1) & id_mask_; id_slots_[j] >= 0; j = (j + 1) & id_mask_) {
    const size_t h = idHome(id_keys_[j]);
    const bool movable = hole <= j ? (h <= hole || h > j) : (h <= hole && h > j);
    if (movable) {
      id_keys_[hole] = id_keys_[j];
      id_slots_[hole] = id_slots_[j];
      hole = j;
    }
  }
  id_slots_[hole] = -1;
}

void Map::rebuildLiveList() {
  live_list_count_ = 0;
  for (int i = 0; i < static_cast<int>(landmarks_.size()); ++i) {
    if (landmarks_[i].alive) live_list_[live_list_count_++] = i;
  }
  live_list_dirty_ = false;
}

int Map::createKeyframe() {
  for (int i = 0; i < static_cast<int>(keyframes_.size()); ++i) {
    if (!keyframes_[i].alive) {
      Keyframe& kf = keyframes_[i];
      kf.alive = true;
      kf.id = nextKeyframeId();
      kf.in_backend = false;
      for (auto& v : kf.landmark_of) std::fill(v.begin(), v.end(), -1);
      return i;
    }
  }
  return -1;
}

void Map::eraseKeyframe(int slot) {
  Keyframe& kf = keyframes_[slot];
  if (!kf.alive) return;
  for (int c = 0; c < kf.features.cameras(); ++c) {
    for (int k = 0; k < kf.features.sets[c].count; ++k) {
      const int lm = kf.landmark_of[c][k];
      if (lm < 0) continue;
      removeObservation(lm, slot, c);
      if (landmarks_[lm].alive && landmarks_[lm].obs_count == 0) eraseLandmark(lm);
    }
  }
  kf.alive = false;
}

int Map::liveKeyframes() const {
  int n = 0;
  for (const Keyframe& k : keyframes_) n += k.alive ? 1 : 0;
  return n;
}

int Map::oldestKeyframe() const {
  int best = -1;
  for (int i = 0; i < static_cast<int>(keyframes_.size()); ++i) {
    if (keyframes_[i].alive && (best < 0 || keyframes_[i].id < keyframes_[best].id)) best = i;
  }
  return best;
}

int Map::oldestWindowKeyframe() const {
  int best = -1;
  for (int i = 0; i < static_cast<int>(keyframes_.size()); ++i) {
    const Keyframe& k = keyframes_[i];
    if (k.alive && k.in_backend && (best < 0 || k.id < keyframes_[best].id)) best = i;
  }
  return best;
}

int Map::newestKeyframe() const {
  int best = -1;
  for (int i = 0; i < static_cast<int>(keyframes_.size()); ++i) {
    if (keyframes_[i].alive && (best < 0 || keyframes_[i].id > keyframes_[best].id)) best = i;
  }
  return best;
}

bool Map::addObservation(int lm, int kf, int cam, int kp) {
  Keyframe& k = keyframes_[kf];
  if (k.landmark_of[cam][kp] >= 0) return false;
  Landmark& l = landmarks_[lm];
  for (int o = 0; o < l.obs_count; ++o) {
    if (l.obs[o].keyframe == kf && l.obs[o].cam == cam) return false;  // one keypoint per camera and keyframe
  }
  if (l.obs_count == kMaxLandmarkObservations) {
    // Drop the oldest keyframe's observation to make room.
    int oldest = 0;
    for (int o = 1; o < l.obs_count; ++o) {
      if (keyframes_[l.obs[o].keyframe].id < keyframes_[l.obs[oldest].keyframe].id) oldest = o;
    }
    const LandmarkObservation old = l.obs[oldest];
    keyframes_[old.keyframe].landmark_of[old.cam][old.kp] = -1;
    l.obs[oldest] = l.obs[--l.obs_count];
  }
  l.obs[l.obs_count++] = LandmarkObservation{kf, static_cast<int16_t>(cam), kp};
  k.landmark_of[cam][kp] = lm;
  return true;
}

void Map::removeObservation(int lm, int kf, int cam) {
  Landmark& l = landmarks_[lm];
  for (int o = 0; o < l.obs_count; ++o) {
    if (l.obs[o].keyframe == kf && l.obs[o].cam == cam) {
      Keyframe& k = keyframes_[kf];
      if (k.landmark_of[cam][l.obs[o].kp] == lm) k.landmark_of[cam][l.obs[o].kp] = -1;
      l.obs[o] = l.obs[--l.obs_count];
      return;
    }
  }
}

int Map::observingKeyframes(int lm) const {
  const Landmark& l = landmarks_[lm];
  int n = 0;
  for (int o = 0; o < l.obs_count; ++o) {
    bool seen = false;
    for (int p = 0; p < o && !seen; ++p) seen = l.obs[p].keyframe == l.obs[o].keyframe;
    n += seen ? 0 : 1;
  }
  return n;
}

void Map::updateLandmarkAppearance(int lm, const Rig& rig, float scale_factor, int levels) {
  Landmark& l = landmarks_[lm];
  if (l.obs_count == 0) return;
  int best = 0, best_sum = 1 << 30;
  for (int a = 0; a < l.obs_count; ++a) {
    const LandmarkObservation& oa = l.obs[a];
    const Descriptor& da = keyframes_[oa.keyframe].features.sets[oa.cam].descriptors[oa.kp];
    int sum = 0;
    for (int b = 0; b < l.obs_count; ++b) {
      const LandmarkObservation& ob = l.obs[b];
      sum += hammingDistance(da, keyframes_[ob.keyframe].features.sets[ob.cam].descriptors[ob.kp]);
    }
    if (sum < best_sum) {
      best_sum = sum;
      best = a;
    }
  }
  const LandmarkObservation& o = l.obs[best];
  const Keyframe& kf = keyframes_[o.keyframe];
  l.descriptor = kf.features.sets[o.cam].descriptors[o.kp];
  // Distance range over which the point stays detectable (ORB-SLAM's scale invariance region), from
  // the newest observation's octave and distance.
  const LandmarkObservation& last = l.obs[l.obs_count - 1];
  const Keyframe& lk = keyframes_[last.keyframe];
  const Vec3 centre = lk.T_w_b * rig.T_b_c(last.cam).t;
  const float dist = static_cast<float>((l.p_w - centre).norm());
  const int octave = lk.features.sets[last.cam].keypoints[last.kp].octave;
  const float level_scale = std::pow(scale_factor, static_cast<float>(octave));
  l.max_distance = dist * level_scale;
  l.min_distance = l.max_distance / std::pow(scale_factor, static_cast<float>(levels - 1));
}

}  // namespace mcslam
