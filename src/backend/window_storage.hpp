#pragma once
// The window's contents in fixed pools: keyframes, landmarks, observations and the camera
// extrinsics, indexed by slot, with the caller's ids mapped to slots. Each landmark keeps a
// singly linked list of its observations.
#include <cstdint>
#include <vector>

#include "fixed_id_map.hpp"
#include "mcslam/backend/sliding_window_solver.hpp"

namespace mcslam::backend {

struct KeyframeState {
  int64_t id = 0;
  SE3 T_w_b;
  uint64_t sequence = 0;  // insertion order: the oldest has the smallest
  bool used = false;
  bool fixed_by_caller = false;
};

struct LandmarkState {
  int64_t id = 0;
  Vec3 p_w = Vec3::Zero();
  int first_observation = -1;
  int num_observations = 0;
  bool used = false;
};

struct ObservationState {
  int keyframe = -1;
  int landmark = -1;
  int camera = 0;
  Vec2 uv = Vec2::Zero();
  double inv_sigma = 1.0;
  int next = -1;  // next observation of the same landmark
  bool used = false;
};

// T = T_lin * exp(d). Extrinsics linked to the marginalization prior keep T_lin (their first
// estimate) and move d; the others are rebased after every step (T_lin = T, d = 0), which makes
// their update the usual right perturbation.
struct ExtrinsicState {
  SE3 T_calib;  // the calibration: mean of the extrinsic prior
  SE3 T_lin;
  Vec6 d = Vec6::Zero();
  SE3 T;
  bool variable = false;          // refined (not the reference camera, refinement on)
  bool in_prior = false;          // linked to the marginalization prior
  bool calibration_prior = true;  // false once an outside estimate showed the calibration wrong
};

// Free slots are kept on a stack, so slots are reused without allocating.
class SlotPool {
 public:
  explicit SlotPool(int capacity) : capacity_(capacity) {
    free_.reserve(capacity);
    refill();
  }
  // Every slot free again, the lowest taken first.
  void refill() {
    free_.clear();
    for (int i = capacity_ - 1; i >= 0; --i) free_.push_back(i);
  }
  bool empty() const { return free_.empty(); }
  int take() {
    const int s = free_.back();
    free_.pop_back();
    return s;
  }
  void give(int s) { free_.push_back(s); }

 private:
  int capacity_ = 0;
  std::vector<int> free_;
};

class WindowStorage {
 public:
  WindowStorage(const Rig& rig, const WindowCapacity& capacity, const SolverOptions& options);
  // Empty, as constructed: no keyframe, landmark or observation; every extrinsic back at its calibration.
  void clear();

  Status addKeyframe(int64_t id, const SE3& T_w_b);
  Status addLandmark(int64_t id, const Vec3& p_w);
  Status addObservation(int64_t keyframe_id, int64_t landmark_id, int camera, const Vec2& uv, double sigma_px);
  Status removeObservation(const ObservationKey& key);
  Status removeLandmark(int64_t id);
  void removeObservationSlot(int obs);  // unlinks from its landmark and frees the slot
  void removeLandmarkSlot(int lm);      // with its observations
  void removeKeyframeSlot(int kf);      // the caller has removed its observations

  int keyframeSlot(int64_t id) const { return keyframe_ids_.find(id); }
  int landmarkSlot(int64_t id) const { return landmark_ids_.find(id); }
  int oldestKeyframe() const;  // slot, -1 when empty

  const Rig& rig() const { return rig_; }
  int numCameras() const { return rig_.size(); }
  const WindowCapacity& capacity() const { return capacity_; }

  std::vector<KeyframeState> keyframes;
  std::vector<LandmarkState> landmarks;
  std::vector<ObservationState> observations;
  std::vector<ExtrinsicState> extrinsics;
  int num_keyframes = 0, num_landmarks = 0, num_observations = 0;

 private:
  Rig rig_;
  WindowCapacity capacity_;
  SlotPool keyframe_slots_, landmark_slots_, observation_slots_;
  FixedIdMap keyframe_ids_, landmark_ids_;
  uint64_t next_sequence_ = 0;
};

}  // namespace mcslam::backend
