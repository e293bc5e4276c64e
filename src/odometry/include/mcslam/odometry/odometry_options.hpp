#pragma once
// Parameters of the visual odometry. Defaults are physical (pixels at octave 0, metres, degrees)
// and hold for any rig; capacities size every buffer at start.
#include "mcslam/geometry/triangulation.hpp"

namespace mcslam {

struct OdometryOptions {
  // Capacities.
  int max_keyframes = 14;    // keyframe pool: the back-end window plus older keyframes kept for tracking
  int window_keyframes = 8;  // keyframes optimized together by the back-end
  int max_landmarks = 16000;

  // ORB pyramid (must match the extractor): sigma of a keypoint = scale_factor^octave pixels.
  float scale_factor = 1.2f;
  int levels = 8;

  // Matching by projection.
  int max_hamming = 80;                 // of 256 bits
  float ratio = 0.85f;                  // best / second best when both are in the same octave
  double track_radius_px = 15.0;        // search radius around the motion-model prediction (octave 0)
  double wide_radius_factor = 4.0;      // radius factor of the second attempt when the first finds too little
  double local_map_radius_px = 4.0;     // radius for the local map, once the pose is known
  int min_matches_for_pose = 12;        // RANSAC needs at least this many matches to try
  int min_tracked = 12;                 // fewer inliers after refinement: the frame is lost
  double strong_tracking_share = 0.25;  // a coarse pose is trusted with this share of the previous frame's inliers
  // A coarse pose needs this share of the matches its attempt holds as inliers: fewer is chance agreement
  // (repeated texture, another place), not a pose.
  double min_consensus_share = 0.1;

  // Tracking loss: the map is dropped and a new one started once this many frames in a row failed and, when place
  // memory may relocalize the rig meanwhile (PlacesOptions::relocalization_timeout_s), this long has passed.
  int max_lost_frames = 5;
  double lost_timeout_s = 0;

  // Keyframes.
  // New keyframe when a frame's tracking inliers fall below this share of the most a frame had since the last
  // one (of all the last keyframe's landmarks in a map whose unit rests on its window: one camera, a start up
  // to scale or roughly metric).
  double keyframe_tracked_ratio = 0.75;
  int keyframe_max_interval = 8;  // frames: at least one keyframe per this many, while the rig moves (below)
  double keyframe_rotation_deg = 8.0;
  double keyframe_translation_ratio = 0.08;  // translation / median scene depth since the last keyframe
  // A rig that has turned and travelled less than this share of both thresholds above since its last keyframe
  // stands still: the interval makes no keyframe of it (in a map that started metric).
  double keyframe_still_share = 0.25;

  // Initialization.
  // Multi-view features a frame needs to start a map by itself (their points known to landmark_max_depth_sigma),
  // and that a map needs, at its start or at a later keyframe, to call its unit the metre: as many points seen at
  // metric_disparity_px or more (Initializer::metricMultiView). Fewer, and the cameras' common points lie too far
  // for their baseline (cameras centimetres apart, a far scene): a few tenths of a pixel of calibration or
  // rectification error, which no pixel noise model sees, move such points' depths by tens of percent, and the map
  // says its unit is only roughly the metre (ScaleStatus::Uncertain).
  int init_min_multiview = 40;
  double metric_disparity_px = 10.0;
  int init_max_reference_age = 40;  // two-frame initialization: renew the reference frame after this many frames
  int init_min_matches = 60;
  // Scale of a rig without overlap, estimated over the map's newest keyframes: the map becomes metric when the
  // estimate's sigma(s)/s is below this (3 sigma inside the 5% the issue asks for), searched within this
  // factor either way of the current unit.
  double scale_max_sigma = 0.05 / 3.0;
  double scale_search_ratio = 30.0;
  // ... and when the estimates combined were gathered over at least this much rotation of the rig: the windows
  // of one turn share their scene and the map's history and can agree on a wrong unit; two corners' worth must
  // confirm it (docs/design/odometry.md).
  double scale_min_rotation_deg = 180.0;
  // Once converged, the map's unit is followed as it drifts: between turns (a straight tells the lever arms
  // nothing) it is taken to random-walk by this relative sigma per keyframe (tools/eval/local_scale.py measures
  // the drift on a recording).
  double scale_drift_per_keyframe = 0.01;
  // A map whose unit is held (no overlap) holds it by all the back-end window's keyframes, not by its two oldest
  // (backend::SolverOptions::hold_window_scale): two keyframes can be close together, and where the side cameras
  // see little the unit drifts through that pair. What it cannot undo is a unit a fast corner's tracking gave the
  // map, which it then keeps.
  bool hold_window_scale = true;

  // Mapping.
  // Multi-view points become landmarks below this relative depth sigma: the same bar as points triangulated
  // across keyframes (the back-end refines both); a stricter one left distant scenes seen by two cameras with
  // too few points to start from.
  double landmark_max_depth_sigma = 0.15;
  int temporal_keyframes = 5;          // previous keyframes searched for new points (newest first)
  TriangulationOptions new_points;     // acceptance of new points triangulated across keyframes
  int cull_min_visible = 8;            // frames a landmark must have been predicted before its ratio counts
  double cull_min_found_ratio = 0.25;  // found / visible below this: erased

  // Back-end.
  bool backend = true;
  int backend_iterations = 6;
  // The solve runs on a thread of its own while tracking goes on with the next frames; its result is applied at a
  // fixed frame, so the output does not depend on timing. A keyframe's own pose is then the tracked one (the
  // optimized pose is what the following frames continue from). The scale estimate of a map started up to scale
  // runs on a thread of its own with it, taken at the next settled keyframe (see `repeatable`), and so does each
  // two-frame initialization attempt, taken at the next frame (InitializationAttempt).
  bool backend_thread = true;
  // true: the scale estimate is taken at the settled keyframe after the one that started it, waiting for it if need
  // be, so that runs repeat exactly (mcslam-run); false: at the first settled keyframe that finds it done, so that
  // no frame waits for it (mcslamd, a live rig). Set by the program, not by the configuration file.
  bool repeatable = true;
  // The frame, counted from the keyframe, before which its solve is applied (1: the next one), for maps that start
  // metric (cameras that overlap). Later spreads the solve over more frame periods instead of stalling one frame
  // for it, but the frames between are tracked against the map before the solve; a new keyframe, a loss or a new
  // map applies it at once. A map started up to scale always uses 1.
  int backend_apply_after_frames = 3;
  // Where a keyframe's solve is applied before the very next frame (one camera, a map started up to scale, or
  // backend_apply_after_frames 1), its new points across time are made on the back-end thread, just before the
  // solve, instead of in the keyframe's frame (Odometry::startDeferredMapping): same map for the next frame, same
  // output. false: in the keyframe's frame, for comparisons. Set by the program, not by the configuration file.
  bool defer_keyframe_mapping = true;
  bool refine_extrinsics = false;
  double extrinsic_sigma_translation = 0.02;  // metres
  double extrinsic_sigma_rotation_deg = 1.0;

  OdometryOptions() {
    // Points from different keyframes need a depth known to 15% and the parallax of ORB-SLAM's rule (about 1
    // degree); where the map's unit rests on them (one camera, no overlap), an inverse depth known to 15% of the
    // scene's instead (LocalMapper::triangulateWithPrevious says why). The back-end refines them from there.
    new_points.max_relative_depth_sigma = 0.15;
    new_points.min_parallax_deg = 1.0;
  }
};

}  // namespace mcslam
