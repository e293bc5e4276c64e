#pragma once
// Tracking (paper IV-C): the pose of every frame against the local map, from the motion model's prediction
// through projection search, RANSAC and refinement, with a descriptor-only fallback; the keyframe decision. It
// owns the motion model, the list of landmarks tracked in the last frame and what it counts per landmark
// (LandmarkTracks); it reads the map (a view for each call) and never writes it. It follows the rig state by
// value at frame boundaries. All memory is allocated at construction.
#include <cstdint>
#include <vector>

#include "mcslam/features/octave_scales.hpp"
#include "mcslam/geometry/absolute_pose_ransac.hpp"
#include "mcslam/geometry/pose_refinement.hpp"
#include "mcslam/odometry/landmark_tracks.hpp"
#include "mcslam/odometry/map.hpp"
#include "mcslam/odometry/odometry_options.hpp"
#include "mcslam/odometry/projection_search.hpp"
#include "mcslam/odometry/rig_state.hpp"

namespace mcslam {

class Tracker {
 public:
  Tracker(const Rig& rig, const OdometryOptions& options, int max_features_per_camera);

  // Takes the rig state by value when it changed (at the start of a frame).
  void follow(const RigState& state);

  // Pose of `frame` against `map` (its live list refreshed). False when lost; `inliers` then says how many the
  // best attempt had. On success the matches (matches()) are the inliers of the pose, and the inliers count
  // towards the keyframe rule's reference (the most since the last keyframe).
  bool track(const Map& map, const FrameFeatures& frame, uint64_t frame_index, SE3& T_w_b, int& inliers);
  // The frame was tracked at T_w_b: the motion model moves on.
  void advance(const SE3& T_w_b);
  // The frame was lost: the motion model carries the pose on (returned).
  const SE3& coast();
  bool needKeyframe(const Map& map, const SE3& T_w_b, int inliers, uint64_t frame_index) const;
  // A keyframe was made of frame `frame_index` at T_w_b.
  void keyframeMade(uint64_t frame_index, const SE3& T_w_b) {
    last_keyframe_frame_ = frame_index;
    last_keyframe_pose_ = T_w_b;
    moved_since_keyframe_ = false;
    most_tracked_since_keyframe_ = 0;
  }
  // Keyframe `slot` is final (optimized, culled): the next frames continue from its pose, with the same velocity
  // (frames tracked since it move with the keyframe's correction), and landmarks the back-end or the culling erased
  // are no longer tracked.
  void keyframeSettled(const Map& map, int slot);
  // The landmarks matched in this frame become the first attempt's list for the next one.
  void rememberTracked(const Map& map, const FrameFeatures& frame, uint64_t frame_index);
  // A new map starts at its keyframe `slot` (of frame `frame_index`): tracking continues from its pose and
  // landmarks, without velocity. `unit_on_window`: the map's unit rests on the back-end window (one camera, a
  // start up to scale or roughly metric), which sets the keyframe rule (needKeyframe).
  void startFrom(const Map& map, int slot, uint64_t frame_index, bool unit_on_window);
  // The map's uncertain unit became metric: keyframes from now on as in a map that started metric.
  void unitLeavesWindow() { unit_on_window_ = false; }
  // The map was dropped: nothing tracked, no velocity (the pose stays).
  void reset();
  // The map took a new unit: positions about `center` times s.
  void rescale(double s, const Vec3& center);

  const SE3& pose() const { return T_w_last_; }  // of the last frame
  // Share of what the local map predicted in the last frame's images (every camera, delivered or not) that
  // `inliers` is, up to 1: it falls as a camera is lost, blurred or blacked out, and as the map stops matching.
  float quality(int inliers) const;
  double rotationTravelled() const { return rotation_travelled_; }  // radians, frame to frame, since the start
  uint64_t recoveries() const { return recoveries_; }  // frames tracked only through the descriptor fallback
  const LandmarkTracks& landmarkTracks() const { return tracks_; }
  // The search and the inlier matches of the last tracked frame (the per-camera extrinsic check reuses them).
  ProjectionSearch& search() { return search_; }
  const FrameMatches& matches() const { return matches_; }

 private:
  // Coarse pose in up to three attempts (see track()); the attempt with the most inliers gives it.
  bool coarsePose(const Map& map, const FrameFeatures& frame, uint64_t frame_index, const SE3& predicted,
                  ProjectionSearchParams& params, SE3& coarse, int& inliers);
  // Pose from the current matches (RANSAC or refinement from `guess`); drops the outlier matches and
  // returns the number of inliers (0 on failure).
  int poseFromMatches(const Map& map, const FrameFeatures& frame, const SE3& guess, bool use_ransac, SE3& T_w_b);
  int searchNewestKeyframeByDescriptor(const Map& map, const FrameFeatures& frame);
  int countKeyframeLandmarks(const Map& map, int slot) const;
  // Mean distance of the landmarks tracked in the last frame (up to 200) from T_w_b.
  double trackedDepth(const Map& map, const SE3& T_w_b) const;

  RigState rig_;  // a copy of the odometry's, taken at frame boundaries
  OdometryOptions options_;
  ProjectionSearch search_;
  FrameMatches matches_;
  AbsolutePoseRansac ransac_;
  PoseRefiner refiner_;
  LandmarkTracks tracks_;
  std::vector<PoseObservation> observations_;  // built from matches_
  std::vector<KeypointRef> observation_refs_;  // which keypoint each observation is
  std::vector<int32_t> last_tracked_;          // landmark slots tracked in the previous frame
  int last_tracked_count_ = 0;
  int last_coarse_inliers_ = 0;  // RANSAC inliers of the previous frame's coarse pose
  OctaveScales octave_scale_{options_.scale_factor};

  bool have_velocity_ = false;
  SE3 T_w_last_;  // pose of the previous frame
  SE3 velocity_;  // relative motion of the last frame step
  uint64_t last_keyframe_frame_ = 0;
  SE3 last_keyframe_pose_;
  bool moved_since_keyframe_ = false;    // T_w_last_ is a frame after the last keyframe, not the keyframe itself
  int last_keyframe_landmarks_ = 0;      // keypoints of the last keyframe with a landmark
  int most_tracked_since_keyframe_ = 0;  // inliers of the best frame tracked since the last keyframe
  bool unit_on_window_ = false;          // the map's unit rests on the window (one camera, no overlap, uncertain)
  int expected_matches_ = 0;  // of the last frame: what the local map predicted in the images (the quality's base)
  double rotation_travelled_ = 0;
  uint64_t recoveries_ = 0;
};

}  // namespace mcslam
