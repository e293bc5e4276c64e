#pragma once
// Parameters of place memory (the `places:` section of the configuration): capacities, sized once at start, and
// the bars of recognition and verification. Defaults hold for any rig.
#include <string>

namespace mcslam {

struct PlacesOptions {
  bool enabled = true;
  std::string vocabulary;  // empty: the shipped vocabulary (defaultVocabularyCandidates())

  // Capacities.
  int max_keyframes = 1500;           // place keyframes of the whole map
  int max_points_per_keyframe = 600;  // points anchored in one keyframe (its landmarks)
  int max_words_per_keyframe = 2000;  // words one keyframe keeps in the database (its heaviest)

  // Recognition: the database's candidates are those above this share of the best score, at most this many.
  float candidate_share = 0.75f;
  int max_candidates = 5;
  int min_words_shared = 20;  // fewer shared words: no candidate

  // Verification (generalized P3P in RANSAC on the matched points, then refinement).
  int max_hamming = 64;      // of 256 bits, for a keypoint-to-point match
  float match_ratio = 0.8f;  // best / second best
  int min_inliers = 50;      // a relocalization needs this many inliers at the refined pose (after the guided search)
  float min_inlier_share = 0.4f;  // ... and this share of the matches the guided search found
  float min_frame_share = 0.05f;  // ... and this share of the frame's keypoints
  int neighbour_keyframes = 2;    // each side of the candidate in its segment: their points join the candidate's

  // Loop closure.
  bool loop_closure = true;
  // One camera's loops, in Sim(3). Off by default: a pose graph spreads a loop's scale correction evenly over
  // the loop, wherever the unit changed (BENCHMARKS.md section 10, "Sim(3) loop closure"). Joining one camera's
  // maps after a loss needs it.
  bool monocular_loop_closure = false;
  int loop_min_keyframes_apart = 30;  // an older keyframe of the same segment is a loop candidate only this far back
  int max_loops = 500;                // loop edges kept in the pose graph
  // Within one odometry map, a loop's path from the old keyframe to the new one is longer than this many times
  // their separation plus this many metres (a return, not a look far ahead).
  double loop_min_path_ratio = 3.0;
  double loop_min_path_m = 2.0;
  // Least standard deviations of a loop's relative pose: the place map's points are triangulated to about 1% of
  // their depth, a few centimetres indoors, and a pose on them is no better. A loop whose correction lies within
  // its uncertainty changes nothing.
  double loop_sigma_translation = 0.02;
  double loop_sigma_rotation_deg = 0.5;
  // The loop closer works on threads of its own: the detection on each keyframe, the correction after a loop.
  // true: the frame waits for them at fixed points (a detection within its keyframe's frame, a correction at the
  // next frame), so that runs repeat exactly (mcslam-run); false: the first frame that finds a result ready takes it,
  // and a frame waits only for a detection whose map it must write (mcslamd, a live rig). Set by the program, not by
  // the configuration file.
  bool repeatable = true;

  // Localizing in a saved map (PlaceMemory::readMap), a recognition corrects the odometry only by what it can have
  // drifted since the last correction: this floor plus this share of the path (and likewise in angle). Visual odometry
  // drifts about 1%; a recognition beyond several times that is repeated texture.
  double drift_floor_m = 0.2;
  double drift_share = 0.05;
  double drift_floor_deg = 1.0;
  double drift_deg_per_m = 0.1;

  // Relocalization: how long the odometry stays lost, trying to relocalize, before it starts a new map.
  double relocalization_timeout_s = 3.0;
};

}  // namespace mcslam
