#pragma once
// The multi-view step of the multi-view features: a frame's pairwise matches joined into tracks with at most one
// keypoint per camera (best matches first), the partners of every track optionally aligned to its reference
// keypoint along the epipolar curve, and every track triangulated from all its rays with depth, reprojection,
// visibility and uncertainty checks before it becomes a multi-view feature of the frame.
//
// A frame: merge(); alignTracks() for every task below alignTaskCount() (none without the alignment), in any
// order and on any threads, each task once; emitTracks(). A track's alignment reads only the frame and writes
// only that track's members, counters and solution, so the result does not depend on the threads. All storage
// is allocated at construction.
#include <cstdint>
#include <span>
#include <vector>

#include "mcslam/calib/rig.hpp"
#include "mcslam/core/image.hpp"
#include "mcslam/features/epipolar_alignment.hpp"
#include "mcslam/features/epipolar_uniqueness.hpp"
#include "mcslam/features/frame_features.hpp"
#include "mcslam/features/keypoint_bearings.hpp"
#include "mcslam/features/multiview_types.hpp"
#include "mcslam/features/octave_scales.hpp"
#include "mcslam/features/overlap_map.hpp"

namespace mcslam {

class TrackBuilder {
 public:
  // For at most `capacity` keypoints per camera and the pairs of `overlap` (which must outlive the builder: it
  // is read, never changed). Throws mcslam::InputError for more than 64 cameras.
  TrackBuilder(const OverlapMap& overlap, const MultiViewOptions& options, int capacity);

  // Joins the frame's matches into tracks and resets the statistics. align: the tracks are aligned
  // (alignTracks()) before they are emitted.
  void merge(const FrameFeatures& f, std::span<const PairMatch> matches, bool align);
  int alignTaskCount() const;
  // Aligns the tracks of `task` and triangulates them. rig: the current extrinsics; images: the frame's, one per
  // camera (an empty one leaves its partners unaligned).
  void alignTracks(const Rig& rig, const KeypointBearings& bearings, const ImageView* images, const FrameFeatures& f,
                   int task);
  // The tracks that pass the checks into f (f.mv, f.mv_refs, f.mv_of; aligned keypoints moved), in track order.
  void emitTracks(const Rig& rig, FrameFeatures& f);
  const MultiViewStats& stats() const { return stats_; }

 private:
  static constexpr int kMaxOctaves = 32;
  // A track member's observation: position, bearing and sigma (after the alignment, when it ran).
  struct Member {
    Vec2 uv;
    Vec3 bearing;
    double sigma_px;
    bool aligned;
  };
  // A track's triangulation and the decision to keep it; its first `size` members are the kept ones.
  struct TrackSolution {
    Vec3 point = Vec3::Zero();
    float relative_depth_sigma = 0;
    int16_t size = 0;
    int16_t medoid = 0;  // the member whose descriptor represents the track
    bool keep = false, has_point = false, metric = false;
  };
  // Where an aligned partner lies on its epipolar curve, for the uniqueness test (ambiguousPair()).
  struct PartnerCurve {
    EpipolarRepeatSearch search;
    Mat2 warp = Mat2::Identity();  // reference pixel offset -> partner pixel offset
    double zncc = 0;               // of the aligned match with the reference
  };
  struct ReferencePatch {
    AlignmentTemplate patch;
    Eigen::Matrix<double, 3, 2> J_pinv;  // reference pixel offset -> bearing offset normal to the ray
    Vec3 bearing;                        // of the reference pixel (the patch's centre)
  };
  int find(int node);
  void joinMatches(const FrameFeatures& f, std::span<const PairMatch> matches);
  void listTracks(const FrameFeatures& f);
  TrackSolution solveTrack(const Rig& rig, const FrameFeatures& f, int32_t* nodes, Member* obs, int size) const;
  TriangulationResult triangulateTrack(const Rig& rig, int32_t* nodes, Member* obs, int& size) const;
  bool hiddenFromNearerCamera(const Rig& rig, const FrameFeatures& f, const int32_t* nodes, const Vec3& point) const;
  int16_t medoidOf(const FrameFeatures& f, const int32_t* nodes, int size) const;
  void emitTrack(FrameFeatures& f, const int32_t* nodes, const Member* obs, const TrackSolution& solution);
  void alignTrack(const Rig& rig, const KeypointBearings& bearings, const ImageView* images, const FrameFeatures& f,
                  int track);
  bool makeReference(const Rig& rig, const KeypointBearings& bearings, const ImageView& image, int cam,
                     const Keypoint& kp, ReferencePatch& ref, Vec2& ref_uv, bool& recentred) const;
  AlignmentStatus alignPartner(const Rig& rig, const ImageView* images, const FrameFeatures& f, int ref_node, int node,
                               const ReferencePatch& ref, Member& out, PartnerCurve* curve) const;
  bool ambiguousPair(const ImageView* images, const int32_t* nodes, const Member* obs, const ReferencePatch& ref,
                     const PartnerCurve& curve) const;
  void prefetchPatches(const ImageView* images, const FrameFeatures& f, int track) const;

  const OverlapMap& overlap_;
  MultiViewOptions options_;
  int capacity_;
  OctaveScales sigma_{options_.octave_scale};  // octave_scale^octave
  int min_metric_views_ = 2;
  MultiViewStats stats_;

  // The merge: union-find over (camera, keypoint) nodes, node = camera * capacity_ + keypoint.
  std::vector<int32_t> parent_;
  std::vector<uint64_t> camera_mask_;    // per root: cameras already in the component
  std::vector<int32_t> order_;           // matches sorted by distance
  std::vector<int32_t> distance_count_;  // counting sort buckets (257)
  std::vector<int32_t> component_of_root_;
  std::vector<int32_t> component_size_;
  std::vector<int32_t> members_;  // nodes grouped by component
  // The tracks of the frame: members_[first, first + size) each, the reference first and the partners that
  // disagree moved past the size once aligned; per track the alignment's counts, per member of members_ its
  // observation (after the alignment; scratch of the emission without it).
  int track_count_ = 0;
  std::vector<int32_t> track_first_;
  std::vector<int32_t> track_size_;
  std::vector<int16_t> track_aligned_;
  std::vector<int16_t> track_disagreeing_;
  std::vector<uint8_t> track_ambiguous_;
  std::vector<Member> aligned_obs_;
  std::vector<TrackSolution> track_solution_;  // per track, when aligned: solved on the alignment's threads
  bool aligned_frame_ = false;                 // this frame's tracks are aligned
};

}  // namespace mcslam
