#pragma once
// A synthetic sequence for odometry tests without rendering: textured points on the walls of a room, each
// with its own descriptor, seen by a rig moving on a closed loop. Every frame's features are the exact
// projections plus pixel noise, with a few descriptor bits flipped, so the odometry logic is tested on
// its own (the image front-end has its own tests).
#include <random>
#include <vector>

#include "mcslam/calib/rig.hpp"
#include "mcslam/dataset/trajectory.hpp"
#include "mcslam/features/frame_features.hpp"

namespace mcslam::test {

// The paper's 5-camera rig (its Kalibr calibration), and from it a rig without overlap: its centre front camera
// and two cameras looking left and right from 10 cm behind it.
Rig isecRig();
Rig nonOverlappingRig3();

struct SyntheticSequenceOptions {
  int frames = 200;
  double rate_hz = 10.0;
  double radius_m = 4.0;  // loop radius (a circle with a wobble); the world's wall stands around it
  // Instead of the circle: a rounded rectangle of straights and quarter-turn corners, as rooms and corridors
  // make a ground robot drive (corner radius 1.2 m: 48 deg/s at 1 m/s). Sides in metres, centred on the loop.
  bool rounded_rectangle = false;
  double rectangle_x_m = 12.0, rectangle_y_m = 8.0;
  double speed_mps = 1.0;
  double noise_px = 0.5;
  int points = 15000;
  // Points that exist in one frame only, this many drawn anew for each frame like the world's (highlights,
  // passers-by, the detector's flicker): a keyframe makes landmarks of them that no later frame finds.
  int one_frame_points = 0;
  int max_features = 1000;
  uint64_t seed = 1;
  int warmup_frames = 60;  // frames before allocations are counted (the map and pools reach steady use)
};

class SyntheticSequence {
 public:
  SyntheticSequence(const Rig& rig, const SyntheticSequenceOptions& options);
  int frames() const { return options_.frames; }
  // Ground truth body pose (body = cam0 frame convention: y down, z forward).
  const StampedPose& truth(int i) const { return truth_[i]; }
  const Trajectory& groundTruth() const { return truth_; }
  // Fills the keypoints and descriptors of frame i (sets, present, t); bearings and multi-view features are
  // left to the front-end's matcher.
  void fill(int i, FrameFeatures& out);

 private:
  struct Point {
    Vec3 p_w;
    Descriptor descriptor;
    int octave = 0;
  };
  Point drawPoint(std::mt19937& rng) const;

  Rig rig_;
  SyntheticSequenceOptions options_;
  std::vector<Point> points_;
  std::vector<Point> frame_points_;  // the one-frame points of the frame being filled
  Trajectory truth_;
  std::mt19937 rng_;
};

// Umeyama-aligned (SE(3), or Sim(3) with `scale`) RMSE of positions, metres.
double alignedRmse(const Trajectory& truth, const Trajectory& estimate, bool scale, double* scale_out = nullptr);

}  // namespace mcslam::test
