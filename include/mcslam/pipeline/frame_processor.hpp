#pragma once
// The boundary between the SLAM core and whatever feeds it (the offline runner, the daemon):
// a rig frame of grey images goes in, a pose estimate comes out. Implementations allocate all
// their memory at construction; process() does not touch the heap after warm-up.
#include <cstdint>

#include "mcslam/calib/rig.hpp"
#include "mcslam/core/image.hpp"
#include "mcslam/core/se3.hpp"
#include "mcslam/core/time.hpp"

namespace mcslam {

enum class TrackingState : uint8_t {
  NotInitialized = 0,  // no map yet (waiting for enough features or parallax)
  Tracking = 1,        // pose estimated against the map
  Lost = 2,            // tracking failed on this frame; the pipeline re-initializes and goes on
};

inline const char* trackingStateName(TrackingState s) {
  switch (s) {
    case TrackingState::NotInitialized: return "not_initialized";
    case TrackingState::Tracking: return "tracking";
    case TrackingState::Lost: return "lost";
  }
  return "?";
}

// One synchronized capture of the rig. images[c] is valid when present[c] is true.
struct RigFrameView {
  Timestamp t = 0;           // capture time, ns
  uint64_t sequence = 0;     // trigger count / frame index
  int cameras = 0;
  const ImageView* images = nullptr;
  const bool* present = nullptr;
};

struct PoseEstimate {
  Timestamp t = 0;           // capture time of the frame, ns
  uint64_t sequence = 0;
  SE3 T_w_b;                 // body in world (world = body at the first frame)
  TrackingState state = TrackingState::NotInitialized;
  float quality = 0;         // 0..1: share of expected landmark matches that were inliers
  bool is_keyframe = false;
  bool valid = false;        // T_w_b holds an estimate
  // T_w_b.t is in metres. False when its unit is arbitrary: one camera, or a rig without overlap whose map
  // started up to scale and has not yet found it.
  bool metric = true;
};

class FrameProcessor {
 public:
  virtual ~FrameProcessor() = default;
  // Processes one rig frame and writes its pose. Never throws on bad image content.
  virtual void process(const RigFrameView& frame, PoseEstimate& out) = 0;

  // process() in two stages, for a caller that runs them on two threads so that the next frame's images are
  // being worked on while this frame is tracked: prepare() is the part that reads the images (the caller may
  // reuse them once it returns), finish() the rest. stageSlots() is how many prepared frames may wait: slots
  // 0..stageSlots()-1, each prepared then finished, frames in capture order, one thread each. 0: no stages,
  // call process(). The poses are those process() gives.
  virtual int stageSlots() const { return 0; }
  virtual void prepare(const RigFrameView& frame, int slot) {
    (void)frame;
    (void)slot;
  }
  virtual void finish(int slot, PoseEstimate& out) {
    (void)slot;
    out = PoseEstimate{};
  }
  // The rig with the extrinsics as the pipeline has refined them online, for writing out at the end of a
  // run (copies, so it may allocate; never call it concurrently with process()). False when the pipeline
  // has none to hand over.
  virtual bool refinedRig(Rig& out) const {
    (void)out;
    return false;
  }
};

}  // namespace mcslam
