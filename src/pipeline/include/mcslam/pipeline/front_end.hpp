#pragma once
// The front-end of a rig frame (paper section IV-A): ORB in every camera on the per-camera workers, then
// the multi-view features between overlapping cameras. Owns the overlap map, computed once.
#include <memory>

#include "mcslam/features/feature_workers.hpp"
#include "mcslam/features/frame_features.hpp"
#include "mcslam/features/multiview_matcher.hpp"
#include "mcslam/pipeline/frame_processor.hpp"
#include "mcslam/pipeline/pipeline_config.hpp"

namespace mcslam {

struct FrontEndTiming {
  double extraction_ms = 0;  // ORB on the workers, with the pairwise multi-view matching that fills their idle time
  double multiview_ms = 0;   // the pairwise matches merged into tracks (aligned on the workers) and triangulated
};

class FrontEnd {
 public:
  FrontEnd(const Rig& rig, const PipelineConfig& config);

  // Fills `out` for the frame. Images whose size differs from the calibration are treated as absent
  // (and counted): a wrong image never reaches the geometry.
  void compute(const RigFrameView& frame, FrameFeatures& out);

  const OverlapMap& overlap() const { return overlap_; }
  const FrontEndTiming& timing() const { return timing_; }
  const MultiViewStats& multiViewStats() const { return matcher_.stats(); }
  uint64_t rejectedImages() const { return rejected_images_; }
  int capacityPerCamera() const { return capacity_; }
  // The multi-view features of the next frames use this extrinsic for camera `cam` (online refinement).
  void setBodyFromCamera(int cam, const SE3& T_b_c) { matcher_.setBodyFromCamera(cam, T_b_c); }

 private:
  // The multi-view matcher's per-camera preparation and camera pairs, as tasks of the ORB workers.
  class MatchingTasks : public ExtractionFollowUp {
   public:
    explicit MatchingTasks(MultiViewMatcher& matcher) : matcher_(matcher) {}
    void setFrame(FrameFeatures* frame) { frame_ = frame; }
    void afterCamera(int camera) override { matcher_.prepareCamera(*frame_, camera); }
    int taskCount() const override { return matcher_.pairCount(); }
    std::pair<int, int> taskCameras(int task) const override { return matcher_.pairCameras(task); }
    void runTask(int task, int thread) override { matcher_.matchPair(*frame_, task, thread); }

   private:
    MultiViewMatcher& matcher_;
    FrameFeatures* frame_ = nullptr;
  };

  // The subpixel alignment of the frame's tracks (on by default), as tasks of the ORB workers once the tracks are
  // merged.
  class AlignmentTasks : public WorkerTasks {
   public:
    explicit AlignmentTasks(MultiViewMatcher& matcher) : matcher_(matcher) {}
    void setFrame(const FrameFeatures* frame) { frame_ = frame; }
    int taskCount() const override { return matcher_.alignTaskCount(); }
    void runTask(int task, int /*thread*/) override { matcher_.alignTracks(*frame_, task); }

   private:
    MultiViewMatcher& matcher_;
    const FrameFeatures* frame_ = nullptr;
  };

  const Rig& rig_;
  int capacity_;
  OverlapMap overlap_;
  FeatureWorkers workers_;
  MultiViewMatcher matcher_;
  MatchingTasks matching_tasks_{matcher_};
  AlignmentTasks alignment_tasks_{matcher_};
  std::vector<ImageView> images_;
  std::unique_ptr<bool[]> present_;
  FrontEndTiming timing_;
  uint64_t rejected_images_ = 0;
};

}  // namespace mcslam
