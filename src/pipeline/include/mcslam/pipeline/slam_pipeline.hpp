#pragma once
// The whole SLAM pipeline behind the FrameProcessor boundary: front-end, odometry and back-end.
#include <memory>
#include <vector>

#include "mcslam/odometry/odometry.hpp"
#include "mcslam/pipeline/front_end.hpp"
#include "mcslam/places/place_memory.hpp"

namespace mcslam {

// A keyframe of the map with its latest optimized pose.
struct KeyframePose {
  int64_t id = -1;
  Timestamp t = 0;
  SE3 T_w_b;
};

class SlamPipeline final : public FrameProcessor {
 public:
  SlamPipeline(const Rig& rig, const PipelineConfig& config);

  void process(const RigFrameView& frame, PoseEstimate& out) override;
  // The front-end in prepare(), the odometry in finish() (FrameProcessor's stages; StageRunner runs them).
  int stageSlots() const override { return static_cast<int>(stages_.size()); }
  void prepare(const RigFrameView& frame, int slot) override;
  void finish(int slot, PoseEstimate& out) override;
  // Completes the back-end work of the last keyframe (finish() does it before the next frame) and a loop
  // correction still being solved: call it after the last frame, before reading the final keyframes.
  void flush();
  // Heap allocations the back-end's and the loop closer's threads have made so far (zero without the counting
  // hooks).
  uint64_t backgroundThreadAllocations() const override;

  // Read on the thread that finishes the frames, between frames.
  const PipelineTiming& timing() const { return timing_; }  // of the last finished frame
  const PipelineTiming* lastTiming() const override { return &timing_; }
  const OdometryStats& stats() const { return odometry_.stats(); }
  // Place memory; nullptr when the configuration turns it off.
  const PlaceMemory* places() const { return places_.get(); }
  // The map file (FrameProcessor): InputError also when place memory is off.
  void loadMap(const std::string& path, bool localize_only) override;
  bool writeMap(std::string& out) const override;
  std::size_t maxMapBytes() const override { return places_ ? places_->maxMapBytes() : 0; }
  bool placeCounters(PlaceCounters& out) const override;
  uint64_t rejectedImages() const { return front_end_.rejectedImages(); }
  int cameras() const { return rig_.size(); }
  bool initialized() const { return odometry_.initialized(); }
  // The start of a map from two frames seen by the last frame (Odometry::lastInitialization()), its poses in the
  // world frame of the poses published; none when that frame has no place in the world (localizing in a map).
  const Odometry::InitializationSpan& initialization() const { return initialization_; }
  // The keyframes in the map now (appended to `out`, which is cleared first): with place memory every keyframe of
  // the place map in the world frame (loop-corrected), else the odometry's local map.
  void keyframes(std::vector<KeyframePose>& out) const;
  Rig refinedRig() const { return odometry_.refinedRig(); }
  // The back-end's current extrinsics (the calibration's when refinement is off).
  bool refinedRig(Rig& out) const override {
    out = odometry_.refinedRig();
    return true;
  }
  const PipelineConfig& config() const { return config_; }

 private:
  // The two halves of process(): the front-end (computeFeatures) and the odometry (track). Each fills its part
  // of `timing` (features_ms; tracking_ms and optimization_ms).
  void computeFeatures(const RigFrameView& frame, FrameFeatures& out, PipelineTiming& timing);
  void track(const FrameFeatures& features, uint64_t sequence, Timestamp t, PoseEstimate& out, PipelineTiming& timing);
  void noteInitialization();

  Rig rig_;
  PipelineConfig config_;
  FrontEnd front_end_;
  Odometry odometry_;
  std::unique_ptr<Vocabulary> vocabulary_;
  std::unique_ptr<PlaceMemory> places_;
  FrameFeatures features_;
  PipelineTiming timing_;
  Odometry::InitializationSpan initialization_;
  struct Stage {
    FrameFeatures features;
    uint64_t sequence = 0;
    Timestamp t = 0;
    PipelineTiming timing;
  };
  std::vector<Stage> stages_;  // prepared frames waiting for finish()
  // With refinement on, the front-end follows the odometry's estimate of a camera whose calibration the per-camera
  // check found wrong (its 2 px epipolar gate would keep rejecting that camera; for the others the calibration
  // is within the gate and stays). The front-end of the n-th frame uses the estimates as of the end of tracking
  // frame n-2, whether it runs before tracking frame n-1 ends (stages, --overlap) or after (process()): the same
  // features either way. One slot per parity, each the odometry's rig state by value: a writer never meets its
  // reader.
  bool handover_ = false;
  std::vector<RigState> rig_after_;  // two slots when handover_
  uint64_t features_computed_ = 0;   // touched by the front-end's thread only
  uint64_t frames_tracked_ = 0;      // by the tracking thread only
};

// Resolves `refine_extrinsics: auto` for the rig and overlap.
OdometryOptions effectiveOdometryOptions(const PipelineConfig& config, const OverlapMap& overlap);

}  // namespace mcslam
