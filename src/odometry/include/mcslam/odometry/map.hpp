#pragma once
// The local map of the odometry: a fixed pool of keyframes (their features and which landmark each
// keypoint observes) and a fixed pool of landmarks (world point, representative descriptor, and the
// keyframe keypoints that observe it). Slots are recycled; ids are not (a landmark's id is unique over the run,
// and it is the id the back-end's window knows it by). Nothing is allocated after construction.
//
// One writer per field: the local mapper creates keyframes and landmarks and keeps their appearance; the window
// bridge writes the back-end's results (poses, positions, in_backend, frozen) and rescales. Tracking only reads
// the map; what it counts per landmark lives in its LandmarkTracks.
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
  int64_t id = -1;  // unique over the run; the back-end's window knows the landmark by it
  Vec3 p_w = Vec3::Zero();
  Descriptor descriptor{};
  int obs_count = 0;
  LandmarkObservation obs[kMaxLandmarkObservations];
  int64_t created_keyframe_id = -1;
  float max_distance = 0;  // distances over which ORB can find it again (scale invariance)
  float min_distance = 0;
  bool in_backend = false;
  bool frozen = false;  // left the back-end by marginalization: kept fixed for tracking
  bool metric = false;  // triangulated with enough certainty to fix scale
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
  // Slot of the live landmark with this id, -1 when none.
  int landmarkSlotOf(int64_t id) const;
  // Slots of the live landmarks in slot order, as of the last refreshLiveList().
  const int32_t* liveLandmarkSlots() const { return live_list_.data(); }
  int liveLandmarkCount() const { return live_list_count_; }
  // Refreshes the compact list of live landmarks after creations and erasures.
  void refreshLiveList() {
    if (live_list_dirty_) rebuildLiveList();
  }

  // Keyframes.
  int createKeyframe();          // slot of a fresh keyframe, -1 when the pool is full
  void eraseKeyframe(int slot);  // removes its observations; landmarks left unobserved die
  Keyframe& keyframe(int slot) { return keyframes_[slot]; }
  const Keyframe& keyframe(int slot) const { return keyframes_[slot]; }
  int keyframeCapacity() const { return static_cast<int>(keyframes_.size()); }
  int liveKeyframes() const;
  int oldestKeyframe() const;        // slot, -1 when none
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

  int64_t nextKeyframeId() { return next_keyframe_id_++; }

 private:
  void rebuildLiveList();
  // Live landmark id -> slot: open addressing, linear probing, deletion by backward shift; sized at construction.
  size_t idHome(int64_t id) const;
  void indexId(int64_t id, int slot);
  void unindexId(int64_t id);

  std::vector<Landmark> landmarks_;
  std::vector<int32_t> free_landmarks_;
  int free_landmark_count_ = 0;
  int live_landmarks_ = 0;
  std::vector<int32_t> live_list_;
  int live_list_count_ = 0;
  bool live_list_dirty_ = true;
  std::vector<Keyframe> keyframes_;
  std::vector<int> medoid_scratch_;
  std::vector<int64_t> id_keys_;
  std::vector<int32_t> id_slots_;  // -1: empty
  size_t id_mask_ = 0;
  int64_t next_landmark_id_ = 0;
  int64_t next_keyframe_id_ = 0;
};

}  // namespace mcslam
