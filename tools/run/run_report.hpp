#pragma once
// What mcslam-run records while it runs, and the files it writes from it.
#include <map>
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
};

class RunReport {
 public:
  void add(const PoseEstimate& pose, const PipelineTiming& timing);
  // After a two-frame initialization at frame `init_index` from reference frame `reference_index`, the
  // frames in between get poses interpolated between the two (they had none of their own).
  void backfill(uint64_t reference_index, uint64_t init_index);
  // Keyframes currently in the map (their latest optimized poses).
  void noteKeyframes(const Map& map);

  Trajectory trajectory() const;  // every frame with a pose
  Trajectory keyframes() const;
  const std::vector<FrameRecord>& frames() const { return frames_; }

  void writeStats(const std::string& path, const SlamPipeline& pipeline, const std::string& dataset, int cameras,
                  double wall_seconds) const;

 private:
  std::vector<FrameRecord> frames_;
  std::map<int64_t, StampedPose> keyframes_;
};

}  // namespace mcslam::run
