#pragma once
// The options and counters of the multi-view features, and the pairwise match that the pair matcher hands to
// the track builder (multiview_matcher.hpp).
#include <cstdint>

#include "mcslam/features/epipolar_alignment.hpp"
#include "mcslam/geometry/triangulation.hpp"

namespace mcslam {

struct MultiViewOptions {
  int max_hamming = 60;                // accept a match only below this descriptor distance (of 256 bits)
  float ratio = 0.8f;                  // best / second best among epipolar-consistent candidates
  double epipolar_px = 2.0;            // gate, in pixels at octave 0 (scaled by the keypoint's octave sigma)
  float octave_scale = 1.2f;           // pyramid scale factor: sigma = scale^octave
  int max_octave_difference = 2;       // scale consistency between the two keypoints
  double duplicate_px = 3.0;           // candidates this close to the best (x octave sigma) are the same corner
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
  // On by default: it removes the partners' pixel quantisation from the disparities, which makes the depths
  // several times more precise; it runs on the front-end's workers after the merge (cost and gain in
  // docs/benchmarks/frontend.md). Off for the keypoints as detected.
  bool align_subpixel = true;
  // With the alignment: the reference pixel moves to where its patch's information lies (informationCentroid()),
  // before the partners are aligned to it, so that the point is placed where its depth was measured.
  bool recentre_reference = true;
  // With the alignment: a track left with two views is dropped when, further along the partner's epipolar curve
  // (depths the matcher accepts), a place that looks like the partner aligns to the reference at least as well
  // as the partner did: the partner may be a repetition of an undetected true one, and no third ray checks its
  // depth (TrackBuilder::ambiguousPair()). Tracks of three or more views are not checked. Off by default: it
  // costs CPU on every frame (BENCHMARKS.md section 3, "Repeating texture").
  bool unique_two_view = false;
  EpipolarAlignmentOptions alignment;

  MultiViewOptions() { triangulation.max_relative_depth_sigma = 0.01; }
};

struct MultiViewStats {
  int pair_matches = 0;  // accepted pairwise matches
  int tracks = 0;        // multi-view features
  int tracks_with_point = 0;
  int metric_tracks = 0;  // with a depth certain to the configured bound
  int dropped = 0;        // tracks rejected by geometry
  int aligned = 0;        // partner keypoints aligned to their reference to subpixel precision
  int disagreeing = 0;    // partner keypoints whose patch did not match the reference's: removed from the track
  int ambiguous = 0;      // two-view tracks dropped: another place on the partner's curve fits the reference as well
};

// A mutual best match between keypoint kp_a of camera cam_a and keypoint kp_b of camera cam_b.
struct PairMatch {
  int16_t cam_a, cam_b;
  int32_t kp_a, kp_b;
  int16_t distance;  // Hamming
};

}  // namespace mcslam
