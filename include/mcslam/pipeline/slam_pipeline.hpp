#pragma once
// The whole SLAM pipeline behind the FrameProcessor boundary: front-end, odometry and back-end.
#include <vector>

#include "mcslam/odometry/odometry.hpp"
#include "mcslam/pipeline/front_end.hpp"

namespace mcslam {

// Milliseconds spent on the last frame, by stage (the paper's Table III split).
struct PipelineTiming {
  double features_ms = 0;      // ORB extraction and multi-view features
  double tracking_ms = 0;      // pose estimation, keyframe decision, new landmarks
  double optimization_ms = 0;  // sliding-window back-end
  double total_ms = 0;
};

class SlamPipeline final : public FrameProcessor {
 public:
  SlamPipeline(const Rig& rig, const PipelineConfig& config);

  void process(const RigFrameView& frame, PoseEstimate& out) override;
  // The front-end in prepare(), the odometry in finish() (FrameProcessor's stages).
  int stageSlots() const override { return static_cast<int>(stages_.size()); }
  void prepare(const RigFrameView& frame, int slot) override;
  void finish(int slot, PoseEstimate& out) override;

  // The two stages of process(), for a caller that overlaps the front-end of the next frame with the odometry
  // of this one (mcslam-run): computeFeatures() may run on another thread, into another FrameFeatures, while
  // track() runs. Each fills its part of `timing` (features_ms; tracking_ms and optimization_ms).
  void computeFeatures(const RigFrameView& frame, FrameFeatures& out, PipelineTiming& timing);
  void track(const FrameFeatures& features, uint64_t sequence, Timestamp t, PoseEstimate& out, PipelineTiming& timing);
  // Completes the back-end work of the last keyframe (track() does it before the next frame): call it after
  // the last frame, before reading the final map.
  void flush() { odometry_.flush(); }
  // A FrameFeatures sized for this pipeline (allocates).
  FrameFeatures makeFrameFeatures() const { return FrameFeatures(rig_.size(), config_.orb.max_features); }

  const PipelineTiming& timing() const { return timing_; }
  const OdometryStats& stats() const { return odometry_.stats(); }
  const FrameFeatures& lastFeatures() const { return features_; }
  const FrontEnd& frontEnd() const { return front_end_; }
  const Odometry& odometry() const { return odometry_; }
  Odometry& odometry() { return odometry_; }
  Rig refinedRig() const { return odometry_.refinedRig(); }
  // The back-end's current extrinsics (the calibration's when refinement is off).
  bool refinedRig(Rig& out) const override {
    out = odometry_.refinedRig();
    return true;
  }
  const PipelineConfig& config() const { return config_; }

 private:
  Rig rig_;
  PipelineConfig config_;
  FrontEnd front_end_;
  Odometry odometry_;
  FrameFeatures features_;
  PipelineTiming timing_;
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
  uint64_t features_computed_ = 0;  // touched by the front-end's thread only
  uint64_t frames_tracked_ = 0;     // by the tracking thread only
};

// Resolves `refine_extrinsics: auto` for the rig and overlap.
OdometryOptions effectiveOdometryOptions(const PipelineConfig& config, const OverlapMap& overlap);

}  // namespace mcslam
