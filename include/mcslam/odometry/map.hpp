#pragma once
// The local map of the odometry: a fixed pool of keyframes (their features and which landmark each
// keypoint observes) and a fixed pool of landmarks (world point, representative descriptor, and the
// keyframe keypoints that observe it). Slots are recycled; nothing is allocated after construction.
#include <cstdint>
#include <vector>

#include "mcslam/calib/rig.hpp"
#include "mcslam/features/frame_features.hpp"

namespace mcslam {

constexpr int kMaxLandmarkObservations = 24;

struct LandmarkObservation {
  int32_t keyframe = -1;  // keyframe slot
  int16_t cam = -1;
  int32_t kp = -1;
};

struct Landmark {
  bool alive = false;
  int64_t id = -1;                 // unique over the run (the back-end's id)
  Vec3 p_w = Vec3::Zero();
  Descriptor descriptor{};
  int obs_count = 0;
  LandmarkObservation obs[kMaxLandmarkObservations];
  int64_t created_keyframe_id = -1;
  uint32_t visible = 0;            // frames it was predicted inside an image
  uint32_t found = 0;              // frames it was matched
  uint64_t matched_frame = ~0ull;  // last frame index it was counted as found in
  uint64_t listed_frame = ~0ull;   // last frame index it was put on the tracked list
  float max_distance = 0;          // distances over which ORB can find it again (scale invariance)
  float min_distance = 0;
  bool in_backend = false;
  bool frozen = false;             // left the back-end by marginalization: kept fixed for tracking
  bool metric = false;             // triangulated with enough certainty to fix scale
};

struct Keyframe {
  bool alive = false;
  int64_t id = -1;
  uint64_t frame_index = 0;
  Timestamp t = 0;
  SE3 T_w_b;
  FrameFeatures features;
  std::vector<std::vector<int32_t>> landmark_of;  // per camera per keypoint: landmark slot or -1
  bool in_backend = false;
};

class Map {
 public:
  Map(const Rig& rig, int max_features_per_camera, int max_keyframes, int max_landmarks);

  void clear();

  // Landmarks.
  int createLandmark(const Vec3& p_w, const Descriptor& d, int64_t keyframe_id);  // slot, -1 when full
  void eraseLandmark(int slot);  // removes its observations from the keyframes too
  Landmark& landmark(int slot) { return landmarks_[slot]; }
  const Landmark& landmark(int slot) const { return landmarks_[slot]; }
  int landmarkCapacity() const { return static_cast<int>(landmarks_.size()); }
  int liveLandmarks() const { return live_landmarks_; }
  // Slots of the live landmarks in slot order, as of the last refreshLiveList().
  const int32_t* liveLandmarkSlots() const { return live_list_.data(); }
  int liveLandmarkCount() const { return live_list_count_; }
  // Refreshes the compact list of live landmarks after creations and erasures.
  void refreshLiveList() {
    if (live_list_dirty_) rebuildLiveList();
  }

  // Keyframes.
  int createKeyframe();  // slot of a fresh keyframe, -1 when the pool is full
  void eraseKeyframe(int slot);  // removes its observations; landmarks left unobserved die
  Keyframe& keyframe(int slot) { return keyframes_[slot]; }
  const Keyframe& keyframe(int slot) const { return keyframes_[slot]; }
  int keyframeCapacity() const { return static_cast<int>(keyframes_.size()); }
  int liveKeyframes() const;
  int oldestKeyframe() const;  // slot, -1 when none
  int oldestWindowKeyframe() const;  // slot of the oldest keyframe in the back-end's window, -1 when none
  int newestKeyframe() const;

  // Links keypoint (cam, kp) of keyframe `kf` to landmark `lm`. When the landmark's observation list
  // is full, its oldest observation is dropped. False when the keypoint is already linked.
  bool addObservation(int lm, int kf, int cam, int kp);
  void removeObservation(int lm, int kf, int cam);
  // Keyframes observing the landmark (distinct).
  int observingKeyframes(int lm) const;

  // Recomputes the representative descriptor (medoid of the observations) and the distance range.
  void updateLandmarkAppearance(int lm, const Rig& rig, float scale_factor, int levels);

  int64_t nextLandmarkId() { return next_landmark_id_++; }
  int64_t nextKeyframeId() { return next_keyframe_id_++; }

 private:
  void rebuildLiveList();

  std::vector<Landmark> landmarks_;
  std::vector<int32_t> free_landmarks_;
  int free_landmark_count_ = 0;
  int live_landmarks_ = 0;
  std::vector<int32_t> live_list_;
  int live_list_count_ = 0;
  bool live_list_dirty_ = true;
  std::vector<Keyframe> keyframes_;
  std::vector<int> medoid_scratch_;
  int64_t next_landmark_id_ = 0;
  int64_t next_keyframe_id_ = 0;
};

}  // namespace mcslam
