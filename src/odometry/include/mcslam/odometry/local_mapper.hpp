#pragma once
// Keyframe insertion (paper IV-C, last paragraph): a new keyframe takes the landmarks tracked in it (and their
// multi-view partners), its metric multi-view features without a landmark become landmarks; landmarks' appearance
// (representative descriptor, distance range) follows their observations; weak landmarks are culled. New points
// across time are TemporalTriangulator's, the back-end's window WindowBridge's. The map, the bridge and the rig
// are handed in for each call; the mapper owns only its list of landmarks whose appearance is due.
#include <cstdint>
#include <span>
#include <vector>

#include "mcslam/features/octave_scales.hpp"
#include "mcslam/odometry/landmark_tracks.hpp"
#include "mcslam/odometry/map.hpp"
#include "mcslam/odometry/map_seed.hpp"
#include "mcslam/odometry/odometry_options.hpp"
#include "mcslam/odometry/projection_search.hpp"

namespace mcslam {

class WindowBridge;

class LocalMapper {
 public:
  explicit LocalMapper(const OdometryOptions& options);

  // Inserts the frame as a keyframe at T_w_b, linking the keypoints matched in `matches`. With
  // `create_multiview_points`, metric multi-view features without a landmark become landmarks. A keyframe that
  // must make room takes the slot of the oldest one outside the window (its lone landmarks leave the window
  // through `bridge`). Returns the keyframe slot (-1 when the map cannot take it).
  int insertKeyframe(Map& map, WindowBridge& bridge, const Rig& rig, const FrameFeatures& frame,
                     const FrameMatches* matches, const SE3& T_w_b, uint64_t frame_index,
                     bool create_multiview_points = true);
  // Inserts the frame as the first keyframe of a map seeded with known points (relocalization): each seed becomes a
  // landmark observed by its keypoint, then multi-view features as in insertKeyframe().
  int insertSeededKeyframe(Map& map, WindowBridge& bridge, const Rig& rig, const FrameFeatures& frame,
                           std::span<const MapSeed> seeds, const SE3& T_w_b, uint64_t frame_index);
  // Recomputes the representative descriptor and distance range of new landmarks (TemporalTriangulator's);
  // with `now` false, at the end of the next keyframe insertion instead.
  void updateAppearance(Map& map, const Rig& rig, std::span<const int32_t> landmarks, bool now);
  // Erases landmarks that are rarely found where predicted (the tracker's counts), or that never got a second
  // keyframe.
  int cull(Map& map, WindowBridge& bridge, int newest_slot, const LandmarkTracks& tracks);
  void reset();

 private:
  int allocateKeyframe(Map& map, WindowBridge& bridge);
  // A keyframe slot holding the frame at T_w_b, without observations yet.
  int startKeyframe(Map& map, WindowBridge& bridge, const FrameFeatures& frame, const SE3& T_w_b, uint64_t frame_index);
  // Metric multi-view features none of whose keypoints observes a landmark become landmarks.
  void createMultiViewLandmarks(Map& map, int slot, const FrameFeatures& frame);
  void linkMultiViewPartners(Map& map, const Rig& rig, int slot, const FrameFeatures& frame);
  void touch(int lm);
  void finishTouched(Map& map, const Rig& rig);

  OdometryOptions options_;
  std::vector<int32_t> touched_;  // landmarks whose appearance is due
  std::vector<uint8_t> touched_flag_;
  int touched_count_ = 0;
  OctaveScales octave_scale_{options_.scale_factor};
};

}  // namespace mcslam
