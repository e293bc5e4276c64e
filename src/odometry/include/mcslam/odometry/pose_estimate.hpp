#pragma once
// What the odometry says of one rig frame: the pose estimate and the tracking state. Below the pipeline so that
// the odometry produces it and the pipeline, the daemon and the tools pass it on.
#include <cstdint>

#include "mcslam/core/se3.hpp"
#include "mcslam/core/time.hpp"

namespace mcslam {

enum class TrackingState : uint8_t {
  NotInitialized = 0,  // no map yet (waiting for enough features or parallax)
  Tracking = 1,        // pose estimated against the map
  Lost = 2,            // tracking failed on this frame; the pipeline re-initializes and goes on
  Localizing = 3,      // tracking, but not yet recognized in the saved map the run reuses: no pose in its world
};

inline const char* trackingStateName(TrackingState s) {
  switch (s) {
    case TrackingState::NotInitialized: return "not_initialized";
    case TrackingState::Tracking: return "tracking";
    case TrackingState::Lost: return "lost";
    case TrackingState::Localizing: return "localizing";
  }
  return "?";
}

struct PoseEstimate {
  Timestamp t = 0;  // capture time of the frame, ns
  uint64_t sequence = 0;
  SE3 T_w_b;  // body in world (world = body at the first frame)
  TrackingState state = TrackingState::NotInitialized;
  float quality = 0;  // 0..1: inliers over the landmark observations the map predicted in the images
  bool is_keyframe = false;
  bool valid = false;  // T_w_b holds an estimate
  // T_w_b.t is in metres. False when its unit is arbitrary (one camera, or a rig without overlap whose map
  // started up to scale and has not yet found it) or only roughly the metre (below).
  bool metric = true;
  // With `metric` false: the unit is the metre as overlapping cameras measured it from points too far for their
  // baseline (a few centimetres apart, a far scene; ScaleStatus::Uncertain): lengths can be tens of percent off.
  bool roughly_metric = false;
  // Times the world estimate has moved so far (loop closures, map merges): a consumer that sees it change knows
  // that the jump between this pose and the one before is a correction of the world, not motion.
  uint16_t world_revision = 0;
  // Where T_w_b lies in the world is the motion model's guess: tracking was lost, relocalization did not bridge
  // the loss, and the new map is not yet joined to the old one (a recognized place clears it, with a new
  // world_revision). Poses are consistent among themselves meanwhile.
  bool unanchored = false;
};

}  // namespace mcslam
