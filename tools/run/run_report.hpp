#pragma once
// What mcslam-run records while it runs, and the files it writes from it.
#include <map>
#include <span>
#include <string>
#include <vector>

#include "mcslam/dataset/trajectory.hpp"
#include "mcslam/pipeline/slam_pipeline.hpp"

namespace mcslam::run {

struct FrameRecord {
  Timestamp t = 0;
  PoseEstimate pose;
  PipelineTiming timing;
  bool interpolated = false;  // filled in after a two-frame initialization
  bool map_start = false;     // a two-frame map started here, published as not initialized, its pose filled in
  // Its position is not in metres (one camera; a rig without overlap before its scale; a roughly metric map:
  // pose.roughly_metric).
  bool unknownScale() const { return pose.valid && !pose.metric; }
};

// A frame whose tracking state differs from the frame before (the first frame counts as one).
struct StateChange {
  std::size_t frame = 0;
  Timestamp t = 0;
  TrackingState state = TrackingState::NotInitialized;
};

// Heap allocations after the warm-up, per thread of the pipeline (mcslam-run links the counting hooks; sanitizer
// builds cannot, and say so with counted = false).
struct AllocationCount {
  bool counted = false;
  uint64_t warmup_frames = 0;
  uint64_t front_end = 0, tracking = 0, background = 0;  // background: the back-end's and loop closer's threads
};

class RunReport {
 public:
  // Returns true when the frame's tracking state differs from the previous frame's (see stateChanges()).
  bool add(const PoseEstimate& pose, const PipelineTiming& timing);
  // A map started from two frames (SlamPipeline::initialization()): the reference frame and the start frame get the
  // poses of their keyframes (the start was published as not initialized: its attempt is taken at the next frame,
  // `seen_index`), and the frames between get poses interpolated between the two (they had none of their own).
  void backfill(const Odometry::InitializationSpan& start, uint64_t seen_index);
  // The keyframes in the map now, with their latest optimized poses (a keyframe that left the map keeps its last).
  void noteKeyframes(const std::vector<KeyframePose>& keyframes);
  // The last frame that was tracked had no metric scale (one camera; a rig without overlap before its scale).
  bool lastTrackedUnscaled() const { return last_tracked_unscaled_; }
  // ... and its unit was roughly the metre (PoseEstimate::roughly_metric).
  bool lastTrackedRoughlyMetric() const { return last_tracked_unscaled_ && last_tracked_roughly_metric_; }

  Trajectory trajectory() const;  // every frame with a pose
  Trajectory keyframes() const;
  const std::vector<FrameRecord>& frames() const { return frames_; }
  const std::vector<StateChange>& stateChanges() const { return changes_; }

  void setAllocations(const AllocationCount& a) { allocations_ = a; }

  void writeStats(const std::string& path, const SlamPipeline& pipeline, const std::string& dataset, int cameras,
                  double wall_seconds) const;
  // One CSV line per frame given to the SLAM (`dataset_index[i]` is the dataset's index of the i-th): its number in
  // the run and in the dataset, its time, the tracking state, whether it made a keyframe, and each stage's time. A
  // percentile of the stats file is a few frames: this says which ones, and what they were doing.
  void writeFrameTimes(const std::string& path, std::span<const std::size_t> dataset_index) const;

 private:
  std::vector<FrameRecord> frames_;
  std::map<int64_t, StampedPose> keyframes_;
  std::vector<StateChange> changes_;
  bool last_tracked_unscaled_ = false;
  bool last_tracked_roughly_metric_ = false;
  AllocationCount allocations_;
};

}  // namespace mcslam::run
