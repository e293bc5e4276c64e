#pragma once
// The boundary between the SLAM core and whatever feeds it (the offline runner, the daemon):
// a rig frame of grey images goes in, a pose estimate comes out. Implementations allocate all
// their memory at construction; process() does not touch the heap after warm-up.
#include <cstdint>

#include "mcslam/calib/rig.hpp"
#include "mcslam/core/image.hpp"
#include "mcslam/core/se3.hpp"
#include "mcslam/core/time.hpp"
#include "mcslam/odometry/pose_estimate.hpp"

namespace mcslam {

// One synchronized capture of the rig. images[c] is valid when present[c] is true.
struct RigFrameView {
  Timestamp t = 0;        // capture time, ns
  uint64_t sequence = 0;  // trigger count / frame index
  int cameras = 0;
  const ImageView* images = nullptr;
  const bool* present = nullptr;
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
