#pragma once
// Matching map landmarks to the keypoints of a rig frame: by projection into every camera around a
// predicted pose (the usual path), or by descriptor alone (recovery when the prediction is wrong).
#include <cstdint>
#include <vector>

#include "mcslam/calib/rig.hpp"
#include "mcslam/odometry/keypoint_grid.hpp"
#include "mcslam/odometry/map.hpp"

namespace mcslam {
class LandmarkTracks;
}

namespace mcslam {

// Which landmark each keypoint of the current frame is matched to, and back: at most one keypoint per
// landmark and camera, at most one landmark per keypoint.
class FrameMatches {
 public:
  void allocate(int cameras, int capacity, int max_landmarks);
  void reset(const FrameFeatures& f);
  int landmarkOf(int cam, int kp) const { return lm_[cam][kp]; }
  int keypointOf(int lm, int cam) const { return kp_of_[static_cast<std::size_t>(lm) * cameras_ + cam]; }
  int distance(int cam, int kp) const { return dist_[cam][kp]; }
  // Assigns unless the keypoint, or the landmark in this camera, already holds an equal or better match;
  // a worse previous match is undone. Returns true when assigned.
  bool offer(int cam, int kp, int lm, int distance);
  void clear(int cam, int kp);
  int count() const { return count_; }

 private:
  int cameras_ = 0;
  int count_ = 0;
  std::vector<std::vector<int32_t>> lm_;
  std::vector<std::vector<int16_t>> dist_;
  std::vector<int32_t> kp_of_;  // [landmark * cameras + cam]
};

struct ProjectionSearchParams {
  double radius_px = 15;
  int max_hamming = 80;
  float ratio = 0.85f;
  float scale_factor = 1.2f;
  int levels = 8;
  bool check_scale = true;  // keypoint octave near the one predicted from the distance
  int camera = -1;          // search this camera only (-1: every camera)
};

class ProjectionSearch {
 public:
  // Sizes its grids for the rig's images; keeps nothing of the rig.
  ProjectionSearch(const Rig& rig, int max_features_per_camera);

  // Buckets the frame's keypoints for radius search. Call once per frame.
  void prepare(const FrameFeatures& frame);

  // Projects the landmarks `slots[0..n)` with the body pose T_w_b into every camera of `rig` (a view for the call:
  // the caller's current extrinsics) and matches each to
  // the best keypoint near its projection. Landmarks already matched in a camera are not searched
  // there again. With `count_visible` (the tracker's counts), landmarks predicted inside an image get visible++.
  int search(const Map& map, const Rig& rig, const int32_t* slots, int n, const SE3& T_w_b, const FrameFeatures& frame,
             const ProjectionSearchParams& params, FrameMatches& matches, LandmarkTracks* count_visible);
  // Of the last search(): the (landmark, camera) pairs whose projection fell inside the camera's image at a scale it
  // could be seen at, in every camera, whether it delivered this frame or not and whether or not the landmark was
  // matched there before. What the map expects the frame to show.
  int predictedInImages() const { return predicted_; }

  // Matches landmarks to keypoints of any camera by descriptor alone (no geometry): for recovery.
  int searchByDescriptor(const Map& map, const int32_t* slots, int n, const FrameFeatures& frame, int max_hamming,
                         float ratio, FrameMatches& matches);

 private:
  std::vector<KeypointGrid> grids_;
  std::vector<SE3> T_c_w_;
  // Per camera: cosine of the widest angle from the optical axis that any pixel of the image sees, with a
  // margin. A point outside that cone cannot project into the image: it is skipped before the lens model.
  std::vector<double> cos_field_;
  int predicted_ = 0;
};

}  // namespace mcslam
