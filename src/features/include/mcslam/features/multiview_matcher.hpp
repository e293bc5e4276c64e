#pragma once
// Multi-view features (paper section IV-A): the coordinator of one rig frame's steps. The keypoints' bearings
// (KeypointBearings), the pairwise matching of overlapping cameras along the epipolar curve (PairMatcher), and
// the tracks joined from the pair matches, aligned and triangulated (TrackBuilder). It owns the rig copy whose
// extrinsics the steps read (a read-only view for each call) and the current frame's images.
#include <utility>

#include "mcslam/calib/rig.hpp"
#include "mcslam/core/image.hpp"
#include "mcslam/features/frame_features.hpp"
#include "mcslam/features/keypoint_bearings.hpp"
#include "mcslam/features/multiview_types.hpp"
#include "mcslam/features/overlap_map.hpp"
#include "mcslam/features/pair_matcher.hpp"
#include "mcslam/features/track_builder.hpp"

namespace mcslam {

class MultiViewMatcher {
 public:
  // Everything is allocated here, for at most `max_features_per_camera` keypoints per camera and `threads`
  // concurrent matchPair() calls (each thread gets its own scratch).
  MultiViewMatcher(const Rig& rig, const OverlapMap& overlap, const MultiViewOptions& options,
                   int max_features_per_camera, int threads = 1);

  // Computes bearings for every keypoint, then the multi-view features. No heap allocation. images (optional,
  // one per camera, valid during the call): the frame's images, for the subpixel alignment of the partners.
  void compute(FrameFeatures& frame, const ImageView* images = nullptr);
  const MultiViewStats& stats() const { return tracks_.stats(); }
  // A new estimate of camera `cam`'s extrinsic (online refinement), for the next compute().
  void setBodyFromCamera(int cam, const SE3& T_b_c) { rig_.cameras[cam].T_b_c = T_b_c; }

  // compute() in steps, for callers that spread a frame over threads (the front-end runs the cameras and the
  // pairs on its ORB workers): beginFrame(); prepareCamera() for every camera once its keypoints and `present`
  // flag are final; matchPair() for every pair once both of its cameras are prepared, in any order and on any
  // threads (distinct `thread` each); finishFrame(). Every pair writes its own slot and finishFrame() takes
  // them in pair order, so the result does not depend on the order or the threads.
  void beginFrame(FrameFeatures& frame, const ImageView* images = nullptr);
  void prepareCamera(FrameFeatures& frame, int camera);
  int pairCount() const { return pairs_.pairCount(); }
  std::pair<int, int> pairCameras(int pair) const { return pairs_.pairCameras(pair); }
  void matchPair(const FrameFeatures& frame, int pair, int thread);
  void finishFrame(FrameFeatures& frame);
  // finishFrame() in steps, for callers that run the subpixel alignment on their threads: mergeFrame();
  // alignTracks() (which also triangulates the tracks it aligned) for every task below alignTaskCount() (0 when
  // the alignment is off or has no images), in any order and on any threads, each task once; emitTracks(). The
  // result is finishFrame()'s, whatever the threads.
  void mergeFrame(FrameFeatures& frame);
  int alignTaskCount() const { return tracks_.alignTaskCount(); }
  void alignTracks(const FrameFeatures& frame, int task);
  void emitTracks(FrameFeatures& frame);

 private:
  Rig rig_;  // a copy: setBodyFromCamera() moves its extrinsics
  KeypointBearings bearings_;
  PairMatcher pairs_;
  TrackBuilder tracks_;
  bool align_subpixel_;
  const ImageView* images_ = nullptr;  // the current frame's, from beginFrame() to emitTracks(), when aligning
};

}  // namespace mcslam
