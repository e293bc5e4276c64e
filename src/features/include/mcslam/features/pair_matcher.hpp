#pragma once
// The pairwise step of the multi-view features: the keypoints of two overlapping cameras of one rig frame matched
// along the epipolar curve (an angular gate, valid for any lens and rig orientation), within the overlap map's
// candidate cells, with a ratio test both ways and mutual best matches only.
//
// A frame: beginFrame(); prepareCamera() for every camera once its keypoints and bearings are final; matchPair()
// for every pair once both of its cameras are prepared, in any order and on any threads (a distinct `thread`
// each); gather(). Every pair writes its own slot and gather() takes them in pair order, so the result does not
// depend on the order or the threads. All storage is allocated at construction.
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "mcslam/calib/rig.hpp"
#include "mcslam/features/frame_features.hpp"
#include "mcslam/features/multiview_types.hpp"
#include "mcslam/features/octave_scales.hpp"
#include "mcslam/features/overlap_map.hpp"

namespace mcslam {

class PairMatcher {
 public:
  // For at most `capacity` keypoints per camera and `threads` concurrent matchPair() calls. `overlap` must
  // outlive the matcher (it is read, never changed).
  PairMatcher(const OverlapMap& overlap, const MultiViewOptions& options, int capacity, int threads);

  void beginFrame();
  // The camera's keypoints rotated into the body frame (rig: the current extrinsics) and bucketed by cell.
  void prepareCamera(const Rig& rig, const FrameFeatures& f, int camera);
  int pairCount() const { return static_cast<int>(overlap_.overlappingPairs().size()); }
  std::pair<int, int> pairCameras(int pair) const { return overlap_.overlappingPairs()[static_cast<size_t>(pair)]; }
  void matchPair(const Rig& rig, const FrameFeatures& f, int pair, int thread);
  // The frame's matches, pair after pair.
  std::span<const PairMatch> gather();

 private:
  static constexpr int kMaxOctaves = 32;
  struct Candidate {  // what the band scan reads, contiguous in plane-angle order
    float angle;
    int32_t b;
    int32_t cell;
    int32_t octave;
    float d[3];  // body-frame bearing
  };
  // Per matching thread: camera j's keypoints sorted by the angle of their epipolar plane about the baseline,
  // the candidate cells of the current cell of camera i marked with a stamp, and the mutual-best bookkeeping.
  struct PairScratch {
    PairScratch(int capacity, int max_cells);
    std::vector<float> plane_angle;  // per keypoint of camera j
    std::vector<int32_t> sorted_b;   // keypoints of j away from the epipole, by plane angle
    std::vector<float> sorted_angle;
    std::vector<Candidate> sorted_candidates;
    std::vector<int32_t> near_epipole_b;  // keypoints of j close to the baseline direction: checked one by one
    std::vector<uint32_t> cell_stamp;     // per cell of camera j
    uint32_t stamp = 0;
    std::vector<int32_t> best_for_b;  // per keypoint of camera j: best keypoint of camera i
    std::vector<int16_t> best_dist_for_b;
    std::vector<int16_t> second_dist_for_b;  // ignoring copies of the best at other octaves
    std::vector<int32_t> candidate_b;        // epipolar-consistent candidates of the current keypoint
    std::vector<int16_t> candidate_dist;
  };
  // The epipolar geometry of one pair (i, j) and camera j's keypoints arranged for the band scan.
  struct PairGeometry {
    Vec3 e, u, v;              // baseline direction and two axes normal to it (body frame)
    double gate[kMaxOctaves];  // sine of the largest angle to the epipolar plane, per octave of the keypoint in j
    float gate_f[kMaxOctaves];
    double window[kMaxOctaves];         // half-width of the plane-angle window, per octave of the keypoint in j
    int octave_start[kMaxOctaves + 1];  // sorted candidates of each octave
    int near = 0;                       // keypoints of j near the epipole
  };
  void bucketKeypoints(const FrameFeatures& f, int camera);
  int matchCameras(const Rig& rig, const FrameFeatures& f, int i, int j, PairScratch& s, PairMatch* out) const;
  void arrangeCandidates(const FrameFeatures& f, int j, PairScratch& s, PairGeometry& g) const;
  int epipolarCandidates(const FrameFeatures& f, int i, int j, int a, const PairGeometry& g, PairScratch& s) const;
  int bestOfCandidates(const FrameFeatures& f, int i, int j, int a, int candidates, PairScratch& s) const;
  void noteForB(const FeatureSet& si, int b, int a, int d, PairScratch& s) const;

  const OverlapMap& overlap_;
  MultiViewOptions options_;
  int capacity_;
  double same_px2_[kMaxOctaves] = {};          // (duplicate_px * sigma(octave))^2
  OctaveScales sigma_{options_.octave_scale};  // octave_scale^octave

  // Keypoints bucketed by cell, per camera (counting sort).
  std::vector<std::vector<int32_t>> cell_start_;  // cells + 1
  std::vector<std::vector<int32_t>> cell_items_;
  std::vector<std::vector<int32_t>> cell_of_;  // per keypoint
  std::vector<std::vector<Vec3>> dir_b_;       // per keypoint: bearing rotated into the body frame
  std::vector<PairScratch> scratch_;           // per thread

  // Pairwise matches: pair p's in its slot of `capacity_` from p * capacity_, gathered to the front in pair order.
  std::vector<PairMatch> matches_;
  std::vector<int32_t> pair_matches_;  // per pair
};

}  // namespace mcslam
