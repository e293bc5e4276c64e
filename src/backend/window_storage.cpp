#include "window_storage.hpp"

#include <cmath>

namespace mcslam::backend {

WindowStorage::WindowStorage(const Rig& rig, const WindowCapacity& capacity, const SolverOptions& options)
    : keyframes(capacity.max_keyframes),
      landmarks(capacity.max_landmarks),
      observations(capacity.max_observations),
      extrinsics(rig.size()),
      rig_(rig),
      capacity_(capacity),
      keyframe_slots_(capacity.max_keyframes),
      landmark_slots_(capacity.max_landmarks),
      observation_slots_(capacity.max_observations),
      keyframe_ids_(capacity.max_keyframes),
      landmark_ids_(capacity.max_landmarks) {
  for (int c = 0; c < rig.size(); ++c) {
    ExtrinsicState& e = extrinsics[c];
    e.T_calib = e.T_lin = e.T = rig.T_b_c(c);
    e.variable = options.refine_extrinsics && c != options.reference_camera;
  }
}

void WindowStorage::clear() {
  for (KeyframeState& k : keyframes) k = KeyframeState{};
  for (LandmarkState& l : landmarks) l = LandmarkState{};
  for (ObservationState& o : observations) o = ObservationState{};
  for (ExtrinsicState& e : extrinsics) {
    e.T_lin = e.T = e.T_calib;
    e.d.setZero();
    e.in_prior = false;
    e.calibration_prior = true;
  }
  num_keyframes = num_landmarks = num_observations = 0;
  keyframe_slots_.refill();
  landmark_slots_.refill();
  observation_slots_.refill();
  keyframe_ids_.clear();
  landmark_ids_.clear();
  next_sequence_ = 0;
}

Status WindowStorage::addKeyframe(int64_t id, const SE3& T_w_b) {
  if (keyframe_ids_.find(id) >= 0) return Status::DuplicateId;
  if (keyframe_slots_.empty()) return Status::CapacityExceeded;
  if (!T_w_b.R.allFinite() || !T_w_b.t.allFinite()) return Status::InvalidValue;
  const int s = keyframe_slots_.take();
  KeyframeState& kf = keyframes[s];
  kf = KeyframeState{};
  kf.id = id;
  kf.T_w_b = T_w_b;
  kf.sequence = next_sequence_++;
  kf.used = true;
  keyframe_ids_.insert(id, s);
  ++num_keyframes;
  return Status::Ok;
}

Status WindowStorage::addLandmark(int64_t id, const Vec3& p_w) {
  if (landmark_ids_.find(id) >= 0) return Status::DuplicateId;
  if (landmark_slots_.empty()) return Status::CapacityExceeded;
  if (!p_w.allFinite()) return Status::InvalidValue;
  const int s = landmark_slots_.take();
  LandmarkState& lm = landmarks[s];
  lm = LandmarkState{};
  lm.id = id;
  lm.p_w = p_w;
  lm.used = true;
  landmark_ids_.insert(id, s);
  ++num_landmarks;
  return Status::Ok;
}

Status WindowStorage::addObservation(int64_t keyframe_id, int64_t landmark_id, int camera, const Vec2& uv,
                                     double sigma_px) {
  const int kf = keyframe_ids_.find(keyframe_id);
  if (kf < 0) return Status::UnknownKeyframe;
  const int lm = landmark_ids_.find(landmark_id);
  if (lm < 0) return Status::UnknownLandmark;
  if (camera < 0 || camera >= numCameras()) return Status::InvalidCamera;
  if (!uv.allFinite() || !(sigma_px > 0) || !std::isfinite(sigma_px)) return Status::InvalidValue;
  for (int o = landmarks[lm].first_observation; o >= 0; o = observations[o].next) {
    if (observations[o].keyframe == kf && observations[o].camera == camera) return Status::DuplicateId;
  }
  if (observation_slots_.empty()) return Status::CapacityExceeded;
  const int s = observation_slots_.take();
  ObservationState& ob = observations[s];
  ob.keyframe = kf;
  ob.landmark = lm;
  ob.camera = camera;
  ob.uv = uv;
  ob.inv_sigma = 1.0 / sigma_px;
  ob.used = true;
  ob.next = landmarks[lm].first_observation;
  landmarks[lm].first_observation = s;
  ++landmarks[lm].num_observations;
  ++num_observations;
  return Status::Ok;
}

Status WindowStorage::removeObservation(const ObservationKey& key) {
  const int kf = keyframe_ids_.find(key.keyframe_id);
  if (kf < 0) return Status::UnknownKeyframe;
  const int lm = landmark_ids_.find(key.landmark_id);
  if (lm < 0) return Status::UnknownLandmark;
  for (int o = landmarks[lm].first_observation; o >= 0; o = observations[o].next) {
    if (observations[o].keyframe == kf && observations[o].camera == key.camera) {
      removeObservationSlot(o);
      return Status::Ok;
    }
  }
  return Status::UnknownObservation;
}

Status WindowStorage::removeLandmark(int64_t id) {
  const int lm = landmark_ids_.find(id);
  if (lm < 0) return Status::UnknownLandmark;
  removeLandmarkSlot(lm);
  return Status::Ok;
}

void WindowStorage::removeObservationSlot(int obs) {
  ObservationState& ob = observations[obs];
  LandmarkState& lm = landmarks[ob.landmark];
  int* link = &lm.first_observation;
  while (*link != obs) link = &observations[*link].next;
  *link = ob.next;
  --lm.num_observations;
  ob.used = false;
  ob.next = -1;
  observation_slots_.give(obs);
  --num_observations;
}

void WindowStorage::removeLandmarkSlot(int lm) {
  LandmarkState& l = landmarks[lm];
  while (l.first_observation >= 0) removeObservationSlot(l.first_observation);
  landmark_ids_.erase(l.id);
  l.used = false;
  landmark_slots_.give(lm);
  --num_landmarks;
}

void WindowStorage::removeKeyframeSlot(int kf) {
  keyframe_ids_.erase(keyframes[kf].id);
  keyframes[kf].used = false;
  keyframe_slots_.give(kf);
  --num_keyframes;
}

int WindowStorage::oldestKeyframe() const {
  int best = -1;
  for (int s = 0; s < int(keyframes.size()); ++s) {
    if (keyframes[s].used && (best < 0 || keyframes[s].sequence < keyframes[best].sequence)) best = s;
  }
  return best;
}

}  // namespace mcslam::backend
