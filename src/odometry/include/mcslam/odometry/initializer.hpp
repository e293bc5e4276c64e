#pragma once
// Map initialization (paper section IV-B). From one rig frame when it has enough metric multi-view
// features; otherwise from two frames, with the generalized relative pose (17-point in RANSAC) for
// rigs of several cameras and the 5-point algorithm for one camera, after a parallax and
// observability check. Two frames of a rig without overlap (no multi-view feature in either) cannot
// observe the metric scale with lever arms of centimetres: such a rig starts up to scale, from the
// 5-point pose of its best camera, and the odometry estimates the scale later over the back-end's
// window (ScaleEstimator). Like the rest of the frame's path, it allocates nothing after construction: a rig
// that lost tracking for good starts a new map through it.
#include <vector>

#include "mcslam/features/frame_features.hpp"
#include "mcslam/geometry/relative_pose.hpp"
#include "mcslam/odometry/odometry_options.hpp"
#include "mcslam/odometry/rig_state.hpp"

namespace mcslam {

class Initializer {
 public:
  Initializer(const Rig& rig, const OdometryOptions& options, int max_features_per_camera);
  // Takes the current rig state (its extrinsics) by value; the odometry calls it before feeding a frame.
  void follow(const RigState& state) { rig_.follow(state); }

  // Multi-view features whose point is certain enough to become a landmark.
  static int usableMultiView(const FrameFeatures& f, double max_depth_sigma);
  // Multi-view features whose point could become a landmark (within `max_depth_sigma`) and whose widest pair of
  // rays meets at `min_disparity_px` or more (multiViewDisparityPx): points whose depth a systematic error of a few
  // tenths of a pixel (calibration, rectification) moves by a few percent at most.
  static int metricMultiView(const FrameFeatures& f, const Rig& rig, double max_depth_sigma, double min_disparity_px);
  // The angle between the widest pair of rays of multi-view feature `t` at its point, in pixels of the two
  // cameras' mean focal length: the disparity of that pair were it rectified.
  static double multiViewDisparityPx(const FrameFeatures& f, int t, const Rig& rig);
  bool oneFrameReady(const FrameFeatures& f) const {
    return usableMultiView(f, options_.landmark_max_depth_sigma) >= options_.init_min_multiview;
  }

  enum class TwoFrame { Waiting, Ready };
  // Feeds a frame to the two-frame initialization. Ready: T_ref_cur (current body frame -> reference body
  // frame) is set and reference() is the first frame. Its translation is metric when lastMetric() (as metric as the
  // frames' multi-view points), else of arbitrary scale (unit translation of one camera).
  TwoFrame feed(const FrameFeatures& f, uint64_t frame_index, SE3& T_ref_cur);
  bool lastMetric() const { return last_metric_; }
  const FrameFeatures& reference() const { return reference_; }
  uint64_t referenceIndex() const { return reference_index_; }
  bool hasReference() const { return has_reference_; }
  void reset() { has_reference_ = false; }
  // Why the last attempt waited (for logs).
  RelativePoseStatus lastStatus() const { return last_status_; }
  int lastMatches() const { return last_matches_; }
  // Matches the frame to the reference by descriptor, camera by camera (what feed() estimates the relative pose
  // from); the matches are then in lastCorrespondences(). Needs a reference (a first feed()).
  int matchToReference(const FrameFeatures& f);
  // The reference-to-frame matches of the last feed() or matchToReference() (tools/study/init_probe.cpp).
  const std::vector<RelativeCorrespondence>& lastCorrespondences() const { return correspondences_; }
  // The relative-pose options feed() uses for a frame (the bearing noise follows the rig's focal length).
  RelativePoseOptions relativePoseOptions(uint64_t frame_index) const;

 private:
  RigState rig_;  // a copy, following the odometry's
  OdometryOptions options_;
  FrameFeatures reference_;
  uint64_t reference_index_ = 0;
  bool has_reference_ = false;
  std::vector<RelativeCorrespondence> correspondences_;
  // matchToReference's one pass over a camera's distances: the nearest current keypoint of each reference
  // keypoint, and the nearest reference keypoint of each current one that passed its own tests (-1 otherwise).
  std::vector<int32_t> best_of_ref_, best_ref_distance_, candidate_of_cur_;
  // Up to scale from the one camera whose 5-point pose has the most inliers (rig without overlap).
  const RelativePoseResult& upToScale(uint64_t frame_index, SE3& T_ref_cur);

  RelativePoseEstimator estimator_;
  RelativePoseResult best_camera_;                      // upToScale's best camera so far (capacity reserved)
  std::vector<RelativeCorrespondence> camera_matches_;  // one camera's share of correspondences_
  bool last_metric_ = true;
  RelativePoseStatus last_status_ = RelativePoseStatus::TooFewCorrespondences;
  int last_matches_ = 0;
};

}  // namespace mcslam
