#pragma once
// The boundary between the SLAM core and whatever feeds it (the offline runner, the daemon):
// a rig frame of grey images goes in, a pose estimate comes out. Implementations allocate all
// their memory at construction; process() does not touch the heap after warm-up.
#include <cstdint>
#include <string>

#include "mcslam/calib/rig.hpp"
#include "mcslam/core/error.hpp"
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

// Milliseconds spent on the last frame, by stage (the paper's Table III split).
struct PipelineTiming {
  double features_ms = 0;      // ORB extraction and multi-view features
  double tracking_ms = 0;      // pose estimation, keyframe decision, new landmarks
  double optimization_ms = 0;  // sliding-window back-end
  double places_ms = 0;        // place memory on the processing thread (relocalization, keyframes, loops)
  double total_ms = 0;
};

// What place memory has done so far, for a daemon's status.
struct PlaceCounters {
  uint64_t relocalizations = 0;
  uint64_t loop_closures = 0;
  uint64_t map_merges = 0;
  uint64_t localization_corrections = 0;
  int64_t keyframes = 0;          // in the place map, a loaded map's included
  uint64_t keyframes_culled = 0;  // let go to make room in the full map
  uint16_t world_revision = 0;
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

  // Place memory. loadMap() (before the first frame) reuses a saved map, only localizing in it when
  // `localize_only`; InputError naming the file when it cannot, or when the processor keeps no map. writeMap()
  // writes the map file's bytes into `out`, allocating nothing when `out` holds maxMapBytes() (false: no map).
  // These and placeCounters() are called between frames, on the thread that finishes them.
  virtual void loadMap(const std::string& path, bool localize_only);
  virtual bool writeMap(std::string& out) const {
    (void)out;
    return false;
  }
  virtual std::size_t maxMapBytes() const { return 0; }
  virtual bool placeCounters(PlaceCounters& out) const {
    (void)out;
    return false;
  }
  // Heap allocations made so far by the processor's own threads beyond prepare()'s and finish()'s (a back-end
  // solver's, say); any thread may ask, at any time.
  virtual uint64_t backgroundThreadAllocations() const { return 0; }
  // The stage times of the last finished frame, read on the finishing thread between frames; nullptr for a
  // processor that does not time its stages.
  virtual const PipelineTiming* lastTiming() const { return nullptr; }
};

inline void FrameProcessor::loadMap(const std::string& path, bool localize_only) {
  (void)localize_only;
  throw InputError(path + ": this frame processor keeps no map");
}

}  // namespace mcslam
