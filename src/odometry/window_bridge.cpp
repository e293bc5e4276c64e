#include "mcslam/odometry/window_bridge.hpp"

#include <algorithm>
#include <cmath>

namespace mcslam {

namespace {

// Exact bounds: every keypoint of a window keyframe observes at most one landmark.
backend::WindowCapacity windowCapacity(const OdometryOptions& o, int cameras, int features_per_camera) {
  backend::WindowCapacity cap;
  cap.max_keyframes = o.window_keyframes;
  cap.max_observations = (o.window_keyframes + 1) * cameras * features_per_camera;  // +1: the keyframe being added
  cap.max_landmarks = std::min(o.max_landmarks, cap.max_observations);
  return cap;
}

// Oldest keyframes the back-end holds: two when the map's scale is not the window's to change (one camera has no
// metric scale; a remembered scale is held), else one.
int gaugeFixedOldest(bool monocular, bool hold_scale) { return monocular || hold_scale ? 2 : 1; }

backend::SolverOptions solverOptions(const OdometryOptions& o, bool monocular) {
  backend::SolverOptions so;
  so.refine_extrinsics = o.refine_extrinsics;
  so.extrinsic_prior.translation = o.extrinsic_sigma_translation;
  so.extrinsic_prior.rotation = o.extrinsic_sigma_rotation_deg * M_PI / 180.0;
  so.gauge_fixed_oldest = gaugeFixedOldest(monocular, false);
  return so;
}

}  // namespace

WindowBridge::WindowBridge(const Rig& calibration, const OdometryOptions& options, int max_features_per_camera)
    : rig_state_(calibration),
      calibration_(calibration),
      options_(options),
      capacity_(max_features_per_camera),
      monocular_(calibration.size() == 1) {
  const int cams = calibration.size();
  calibration_dropped_.assign(cams, 0);
  outliers_.resize(static_cast<std::size_t>(cams) * max_features_per_camera * options.window_keyframes);
  if (options.backend) {
    solver_ = std::make_unique<backend::SlidingWindowSolver>(
        calibration, windowCapacity(options, cams, max_features_per_camera), solverOptions(options, monocular_));
    solve_.bridge = this;
    solve_.iterations = options.backend_iterations;
    if (options.backend_thread) task_ = std::make_unique<BackgroundTask>();
  }
}

WindowBridge::~WindowBridge() {
  if (task_) task_->wait();  // the solver must outlive a solve in flight
}

void WindowBridge::reset() {
  if (task_) task_->collect();
  solving_ = false;  // the window is dropped with the map: its last result does not matter
  if (!solver_) return;
  // An empty window (the old one's keyframes and landmarks are gone with the map), on the same prior, starting from
  // the current extrinsics. Cleared, not rebuilt: a relocalization allocates nothing.
  solver_->clear();
  for (int c = 0; c < rig_state_.cameras(); ++c) {  // refused where not refined
    solver_->setExtrinsic(c, rig_state_.T_b_c(c), !calibration_dropped_[c]);
  }
}

void WindowBridge::adoptSolvedExtrinsics() {
  if (!solver_) return;
  for (int c = 0; c < rig_state_.cameras(); ++c) rig_state_.setExtrinsic(c, solver_->extrinsic(c));
}

void WindowBridge::reestimateExtrinsic(int cam, const SE3& T_b_c) {
  rig_state_.setExtrinsic(cam, T_b_c);
  rig_state_.markReestimated(cam);
  if (!solver_ || solving_ || solver_->setExtrinsic(cam, T_b_c) != backend::Status::Ok) return;
  calibration_dropped_[cam] = 1;
}

void WindowBridge::rescale(Map& map, double s, const Vec3& center) {
  for (int i = 0; i < map.keyframeCapacity(); ++i) {
    Keyframe& k = map.keyframe(i);
    if (!k.alive) continue;
    k.T_w_b.t = center + s * (k.T_w_b.t - center);
    if (solver_ && k.in_backend) solver_->setKeyframePose(k.id, k.T_w_b);
  }
  for (int lm = 0; lm < map.landmarkCapacity(); ++lm) {
    Landmark& l = map.landmark(lm);
    if (!l.alive) continue;
    l.p_w = center + s * (l.p_w - center) - (s - 1) * leverArmOfNewestObserver(map, l);
    if (solver_ && l.in_backend) solver_->setLandmarkPosition(l.id, l.p_w);
    // ORB finds it again over distances that scale with it.
    l.min_distance *= static_cast<float>(s);
    l.max_distance *= static_cast<float>(s);
  }
}

// What was in the wrong unit is the rig's motion, not its lever arms: a landmark's depth along the ray of a camera
// that saw it is what scales, about that camera's centre. Scaling about the body would move the point off every
// ray by (s - 1) times the lever arm, and the next frame's pose with it.
// The newest observer is the camera tracking continues near; older ones differ from it only by the rig's rotation
// since.
Vec3 WindowBridge::leverArmOfNewestObserver(const Map& map, const Landmark& l) const {
  int newest = -1;
  int64_t newest_id = -1;
  for (int o = 0; o < l.obs_count; ++o) {
    const Keyframe& k = map.keyframe(l.obs[o].keyframe);
    if (k.alive && k.id > newest_id) {
      newest_id = k.id;
      newest = o;
    }
  }
  if (newest < 0) return Vec3::Zero();
  const LandmarkObservation& o = l.obs[newest];
  return map.keyframe(o.keyframe).T_w_b.R * rig_state_.T_b_c(o.cam).t;
}

void WindowBridge::holdScale(bool hold) {
  if (!solver_) return;
  const bool by_window = hold && options_.hold_window_scale;
  solver_->setHoldWindowScale(by_window);
  solver_->setGaugeFixedOldest(by_window ? 1 : gaugeFixedOldest(monocular_, hold));
}

Rig WindowBridge::refinedRig() const {
  if (task_) task_->wait();
  return solver_ ? solver_->refinedRig() : rig_state_.rig();
}

int WindowBridge::keyframeSlotOfId(const Map& map, int64_t id) const {
  for (int i = 0; i < map.keyframeCapacity(); ++i) {
    if (map.keyframe(i).alive && map.keyframe(i).id == id) return i;
  }
  return -1;
}

void WindowBridge::removeLandmark(Map& map, int lm) {
  Landmark& l = map.landmark(lm);
  if (solver_ && l.in_backend) solver_->removeLandmark(l.id);
  l.in_backend = false;
}

bool WindowBridge::optimize(Map& map, int slot) {
  if (!beginSolve(map, slot)) return false;
  return finishSolve(map);
}

bool WindowBridge::beginSolve(Map& map, int slot) {
  if (!solver_) return false;
  finishSolve(map);  // one window at a time
  if (!feed(map, slot)) return false;
  startSolve(map, -1, nullptr);
  return true;
}

bool WindowBridge::beginSolveAfter(Map& map, int slot, BackgroundJob& mapping) {
  if (!solver_) {
    mapping.run();
    return false;
  }
  finishSolve(map);  // one window at a time
  startSolve(map, slot, &mapping);
  return true;
}

void WindowBridge::startSolve(Map& map, int slot, BackgroundJob* mapping) {
  solve_.map = &map;
  solve_.slot = slot;
  solve_.mapping = mapping;
  solving_ = true;
  if (task_) {
    task_->start(solve_);
  } else {
    solve_.run();
  }
}

void WindowBridge::WindowSolve::run() {
  fed = true;
  if (slot >= 0) {
    if (mapping) mapping->run();
    fed = bridge->feed(*map, slot);
  }
  if (fed) summary = bridge->solver_->solve(iterations);
}

void WindowBridge::wait() const {
  if (task_) task_->wait();
}

bool WindowBridge::feed(Map& map, int slot) {
  Keyframe& kf = map.keyframe(slot);
  if (solver_->isFull()) {
    const std::optional<int64_t> oldest = solver_->oldestKeyframe();
    if (solver_->marginalizeOldest() != backend::Status::Ok) return false;
    if (oldest) {
      const int os = keyframeSlotOfId(map, *oldest);
      if (os >= 0) map.keyframe(os).in_backend = false;
    }
    for (const int64_t id : solver_->marginalizedLandmarks()) {
      const int lm = map.landmarkSlotOf(id);
      if (lm < 0) continue;
      Landmark& l = map.landmark(lm);
      l.in_backend = false;
      l.frozen = true;
    }
  }
  if (solver_->addKeyframe(kf.id, kf.T_w_b) != backend::Status::Ok) return false;
  kf.in_backend = true;
  addLandmarkObservations(map, kf);
  return true;
}

void WindowBridge::addLandmarkObservations(Map& map, const Keyframe& kf) {
  for (int c = 0; c < kf.features.cameras(); ++c) {
    for (int k = 0; k < kf.features.sets[c].count; ++k) {
      const int lm = kf.landmark_of[c][k];
      if (lm < 0) continue;
      Landmark& l = map.landmark(lm);
      if (l.in_backend) {
        const Keypoint& kp = kf.features.sets[c].keypoints[k];
        solver_->addObservation(kf.id, l.id, c, Vec2(kp.x, kp.y), octave_scale_[kp.octave]);
        continue;
      }
      if (l.frozen) continue;
      // A landmark enters the window once two window keyframes observe it.
      int in_window = 0;
      for (int o = 0; o < l.obs_count; ++o) in_window += map.keyframe(l.obs[o].keyframe).in_backend ? 1 : 0;
      if (in_window < 2 || solver_->addLandmark(l.id, l.p_w) != backend::Status::Ok) continue;
      l.in_backend = true;
      for (int o = 0; o < l.obs_count; ++o) {
        const Keyframe& ok = map.keyframe(l.obs[o].keyframe);
        if (!ok.in_backend) continue;
        const Keypoint& kp = ok.features.sets[l.obs[o].cam].keypoints[l.obs[o].kp];
        solver_->addObservation(ok.id, l.id, l.obs[o].cam, Vec2(kp.x, kp.y), octave_scale_[kp.octave]);
      }
    }
  }
}

bool WindowBridge::finishSolve(Map& map) {
  if (!solving_) return false;
  solving_ = false;
  if (task_) task_->collect();
  if (!solve_.fed) return false;
  const backend::SolveSummary& summary = solve_.summary;
  ++solves_;
  removeOutliers(map);
  if (!summary.failed) writeBack(map);
  return !summary.failed;
}

void WindowBridge::removeOutliers(Map& map) {
  // Outliers leave the window and the map (copied first: removing changes the solver's list).
  int no = 0;
  for (const backend::ObservationKey& o : solver_->outliers()) {
    if (no < static_cast<int>(outliers_.size())) outliers_[no++] = o;
  }
  for (int i = 0; i < no; ++i) {
    const backend::ObservationKey& o = outliers_[i];
    const int lm = map.landmarkSlotOf(o.landmark_id);  // -1: an earlier outlier's removal erased it
    const int ks = keyframeSlotOfId(map, o.keyframe_id);
    solver_->removeObservation(o);
    if (lm < 0) continue;
    if (ks >= 0) map.removeObservation(lm, ks, o.camera);
    Landmark& l = map.landmark(lm);
    if (!l.alive) continue;
    int in_window = 0;
    for (int j = 0; j < l.obs_count; ++j) in_window += map.keyframe(l.obs[j].keyframe).in_backend ? 1 : 0;
    if (in_window < 2) removeLandmark(map, lm);
    if (l.obs_count == 0) map.eraseLandmark(lm);
  }
}

void WindowBridge::writeBack(Map& map) {
  for (int i = 0; i < map.keyframeCapacity(); ++i) {
    Keyframe& k = map.keyframe(i);
    if (k.alive && k.in_backend) solver_->keyframePose(k.id, k.T_w_b);
  }
  map.refreshLiveList();
  for (int i = 0; i < map.liveLandmarkCount(); ++i) {
    Landmark& l = map.landmark(map.liveLandmarkSlots()[i]);
    if (l.in_backend) solver_->landmarkPosition(l.id, l.p_w);
  }
}

}  // namespace mcslam
