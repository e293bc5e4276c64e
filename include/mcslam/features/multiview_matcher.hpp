#pragma once
// Multi-view features (paper section IV-A): cell-wise cross matching between overlapping cameras of
// one rig frame, an epipolar gate in angular form (valid for any lens and rig orientation), merging of
// the pairwise matches into tracks with at most one keypoint per camera, and triangulation from all
// rays with depth, reprojection and uncertainty checks.
#include <cstdint>
#include <utility>
#include <vector>

#include "mcslam/calib/rig.hpp"
#include "mcslam/core/image.hpp"
#include "mcslam/features/epipolar_alignment.hpp"
#include "mcslam/features/frame_features.hpp"
#include "mcslam/features/octave_scales.hpp"
#include "mcslam/features/overlap_map.hpp"
#include "mcslam/geometry/triangulation.hpp"

namespace mcslam {

struct MultiViewOptions {
  int max_hamming = 60;             // accept a match only below this descriptor distance (of 256 bits)
  float ratio = 0.8f;               // best / second best among epipolar-consistent candidates
  double epipolar_px = 2.0;         // gate, in pixels at octave 0 (scaled by the keypoint's octave sigma)
  float octave_scale = 1.2f;        // pyramid scale factor: sigma = scale^octave
  int max_octave_difference = 2;    // scale consistency between the two keypoints
  double duplicate_px = 3.0;        // candidates this close to the best (x octave sigma) are the same corner
  TriangulationOptions triangulation;  // max_relative_depth_sigma decides which points are metric
  // A two-view match has no geometric check of its depth (a wrong partner along the epipolar curve is just
  // another depth). It is dropped when a present camera nearer to one of its two cameras than they are to
  // each other (a smaller change of view) should see its point, more than this margin inside the image,
  // and contributed no keypoint: a match found across the wider baseline but not the narrower one.
  bool two_view_visibility_check = true;
  double visibility_margin_px = 24.0;
  // Rays a metric point needs (a third ray verifies the depth); 0: 3 when some camera overlaps two others,
  // else 2 (stereo pairs, rings of pairwise overlaps).
  int min_metric_views = 0;
  // Subpixel alignment of every partner keypoint to the track's reference keypoint (the finest octave) along
  // the epipolar curve, when the images are given to compute(); partners whose patches disagree leave the track.
  // On by default: depth 2-3x more precise for about 2.5 ms of wall time per 5-camera rig frame, on the
  // front-end's workers after the merge (docs/benchmarks/frontend.md). Off for the keypoints as detected.
  bool align_subpixel = true;
  // With the alignment: the reference pixel moves to where its patch's information lies (informationCentroid()),
  // before the partners are aligned to it, so that the point is placed where its depth was measured.
  bool recentre_reference = true;
  EpipolarAlignmentOptions alignment;

  MultiViewOptions() { triangulation.max_relative_depth_sigma = 0.01; }
};

struct MultiViewStats {
  int pair_matches = 0;     // accepted pairwise matches
  int tracks = 0;           // multi-view features
  int tracks_with_point = 0;
  int metric_tracks = 0;    // with a depth certain to the configured bound
  int dropped = 0;          // tracks rejected by geometry
  int aligned = 0;          // partner keypoints aligned to their reference to subpixel precision
  int disagreeing = 0;      // partner keypoints whose patch did not match the reference's: removed from the track
};

class MultiViewMatcher {
 public:
  // Everything is allocated here, for at most `max_features_per_camera` keypoints per camera and `threads`
  // concurrent matchPair() calls (each thread gets its own scratch).
  MultiViewMatcher(const Rig& rig, const OverlapMap& overlap, const MultiViewOptions& options,
                   int max_features_per_camera, int threads = 1);

  // Computes bearings for every keypoint, then the multi-view features. No heap allocation. images (optional,
  // one per camera, valid during the call): the frame's images, for the subpixel alignment of the partners.
  void compute(FrameFeatures& frame, const ImageView* images = nullptr);
  const MultiViewStats& stats() const { return stats_; }
  // A new estimate of camera `cam`'s extrinsic (online refinement), for the next compute().
  void setBodyFromCamera(int cam, const SE3& T_b_c) { rig_.cameras[cam].T_b_c = T_b_c; }

  // compute() in steps, for callers that spread a frame over threads (the front-end runs the cameras and the
  // pairs on its ORB workers): beginFrame(); prepareCamera() for every camera once its keypoints and `present`
  // flag are final; matchPair() for every pair once both of its cameras are prepared, in any order and on any
  // threads (distinct `thread` each); finishFrame(). Every pair writes its own slot and finishFrame() takes
  // them in pair order, so the result does not depend on the order or the threads.
  void beginFrame(FrameFeatures& frame, const ImageView* images = nullptr);
  void prepareCamera(FrameFeatures& frame, int camera);
  int pairCount() const { return static_cast<int>(overlap_.overlappingPairs().size()); }
  std::pair<int, int> pairCameras(int pair) const { return overlap_.overlappingPairs()[static_cast<size_t>(pair)]; }
  void matchPair(const FrameFeatures& frame, int pair, int thread);
  void finishFrame(FrameFeatures& frame);
  // finishFrame() in steps, for callers that run the subpixel alignment on their threads: mergeFrame();
  // alignTracks() (which also triangulates the tracks it aligned) for every task below alignTaskCount() (0 when
  // the alignment is off or has no images), in any order and on any threads, each task once; emitTracks(). The
  // result is finishFrame()'s, whatever the threads.
  void mergeFrame(FrameFeatures& frame);
  int alignTaskCount() const;
  void alignTracks(const FrameFeatures& frame, int task);
  void emitTracks(FrameFeatures& frame);

 private:
  struct Match {
    int16_t cam_a, cam_b;
    int32_t kp_a, kp_b;
    int16_t distance;
  };
  struct PairScratch;
  void computeBearings(FrameFeatures& f, int camera);
  void bucketKeypoints(const FrameFeatures& f, int camera);
  int matchCameras(const FrameFeatures& f, int i, int j, PairScratch& s, Match* out) const;
  void noteForB(const FeatureSet& si, int b, int a, int d, PairScratch& s) const;
  void gatherMatches();
  void mergeTracks(FrameFeatures& f);
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
  TrackSolution solveTrack(const FrameFeatures& f, int32_t* nodes, Member* obs, int size) const;
  void emitTrack(FrameFeatures& f, const int32_t* nodes, const Member* obs, const TrackSolution& solution);
  struct ReferencePatch {
    AlignmentTemplate patch;
    Eigen::Matrix<double, 3, 2> J_pinv;  // reference pixel offset -> bearing offset normal to the ray
    Vec3 bearing;                        // of the reference pixel (the patch's centre)
  };
  void alignTrack(const FrameFeatures& f, int track);
  AlignmentStatus alignPartner(const FrameFeatures& f, int ref_node, int node, const ReferencePatch& ref,
                               Member& out) const;
  void prefetchPatches(const FrameFeatures& f, int track) const;
  bool bearingOf(int cam, const Vec2& uv, Vec3& bearing) const;
  int find(int node);

  Rig rig_;  // a copy: setBodyFromCamera() moves its extrinsics
  const OverlapMap& overlap_;
  MultiViewOptions options_;
  int capacity_;
  MultiViewStats stats_;
  static constexpr int kMaxOctaves = 32;
  double same_px2_[kMaxOctaves] = {};  // (duplicate_px * sigma(octave))^2
  OctaveScales sigma_{options_.octave_scale};  // octave_scale^octave
  int min_metric_views_ = 2;

  // Keypoints bucketed by cell, per camera (counting sort).
  std::vector<std::vector<int32_t>> cell_start_;  // cells + 1
  std::vector<std::vector<int32_t>> cell_items_;
  std::vector<std::vector<int32_t>> cell_of_;     // per keypoint
  std::vector<std::vector<Vec3>> dir_b_;          // per keypoint: bearing rotated into the body frame
  // Per camera: bearings on a pixel grid (zero where the model has none); a keypoint's bearing is interpolated
  // and polished with one Gauss-Newton step on the projection instead of iterative undistortion.
  static constexpr int kBearingGridStep = 8;
  std::vector<std::vector<Vec3>> bearing_grid_;
  std::vector<int> bearing_grid_cols_;

  // Per matching thread: camera j's keypoints sorted by the angle of their epipolar plane about the baseline,
  // the candidate cells of the current cell of camera i marked with a stamp, and the mutual-best bookkeeping.
  struct Candidate {                     // what the band scan reads, contiguous in plane-angle order
    float angle;
    int32_t b;
    int32_t cell;
    int32_t octave;
    float d[3];                          // body-frame bearing
  };
  struct PairScratch {
    PairScratch(int capacity, int max_cells);
    std::vector<float> plane_angle;       // per keypoint of camera j
    std::vector<int32_t> sorted_b;        // keypoints of j away from the epipole, by plane angle
    std::vector<float> sorted_angle;
    std::vector<Candidate> sorted_candidates;
    std::vector<int32_t> near_epipole_b;  // keypoints of j close to the baseline direction: checked one by one
    std::vector<uint32_t> cell_stamp;     // per cell of camera j
    uint32_t stamp = 0;
    std::vector<int32_t> best_for_b;      // per keypoint of camera j: best keypoint of camera i
    std::vector<int16_t> best_dist_for_b;
    std::vector<int16_t> second_dist_for_b;  // ignoring copies of the best at other octaves
    std::vector<int32_t> candidate_b;     // epipolar-consistent candidates of the current keypoint
    std::vector<int16_t> candidate_dist;
  };
  std::vector<PairScratch> scratch_;

  // Pairwise matches (pair p's in its slot of `capacity_` from p * capacity_, gathered to the front in pair
  // order by finishFrame()) and their merge.
  std::vector<Match> matches_;
  std::vector<int32_t> pair_matches_;    // per pair
  int match_count_ = 0;
  std::vector<int32_t> parent_;          // union-find over (camera, keypoint) nodes
  std::vector<uint64_t> camera_mask_;    // per root: cameras already in the component
  std::vector<int32_t> order_;           // matches sorted by distance
  std::vector<int32_t> distance_count_;  // counting sort buckets (257)
  std::vector<int32_t> component_of_root_;
  std::vector<int32_t> component_size_;
  std::vector<int32_t> members_;         // nodes grouped by component
  // The tracks of the frame (mergeFrame()): members_[first, first + size) each, the reference first and the
  // partners that disagree moved past the size once aligned; per track the alignment's counts, per member of
  // members_ its observation (after the alignment; scratch of the emission without it).
  int track_count_ = 0;
  std::vector<int32_t> track_first_;
  std::vector<int32_t> track_size_;
  std::vector<int16_t> track_aligned_;
  std::vector<int16_t> track_disagreeing_;
  std::vector<Member> aligned_obs_;
  std::vector<TrackSolution> track_solution_;  // per track, when aligned: solved on the alignment's threads
  bool aligned_frame_ = false;  // this frame's tracks are aligned (alignment on, images given)
  const ImageView* images_ = nullptr;  // the current frame's, during compute()
};

}  // namespace mcslam
