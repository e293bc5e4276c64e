#pragma once
// The rig as the odometry currently estimates it: every camera's extrinsic, which cameras the per-camera check
// re-estimated, the status of the map's metric scale, and a version that moves with every change. One object
// produces it (the back-end side: WindowBridge); everyone else receives a copy by value at a frame boundary
// (follow()) and never holds a reference into the producer's. Copying between states of the same rig allocates
// nothing (the vectors keep their sizes).
#include <cstdint>
#include <vector>

#include "mcslam/calib/rig.hpp"

namespace mcslam {

enum class ScaleStatus : uint8_t {
  Metric,     // the map's unit is the metre (multi-view features, or a window estimate that converged)
  Unscaled,   // a map started up to scale (rig without overlap): its unit waits for the window estimates
  Monocular,  // one camera: no metric scale to find
  // Overlapping cameras whose common points lie too far for their baseline (a few centimetres, a far scene): the
  // map's unit is the metre as points known to tens of percent tell it, held by the window like an unscaled
  // map's, and not reported as metric until a keyframe sees enough metric multi-view points
  // (OdometryOptions::init_min_multiview).
  Uncertain,
};

class RigState {
 public:
  // The calibration, nothing re-estimated, version 0; the scale Metric for a rig, Monocular for one camera.
  explicit RigState(const Rig& calibration);

  const Rig& rig() const { return rig_; }
  int cameras() const { return rig_.size(); }
  const SE3& T_b_c(int cam) const { return rig_.T_b_c(cam); }
  bool reestimated(int cam) const { return reestimated_[cam] != 0; }
  ScaleStatus scale() const { return scale_; }
  // Poses in metres (the flag PoseEstimate::metric carries).
  bool metric() const { return scale_ == ScaleStatus::Metric; }
  // False while a map started up to scale waits for its unit; true otherwise (one camera never waits, nor an
  // uncertain unit: a window estimate would fit the same far points that gave it).
  bool scaleConverged() const { return scale_ != ScaleStatus::Unscaled; }
  uint64_t version() const { return version_; }

  // The producer's side. Each moves the version when, and only when, the value changes.
  void setExtrinsic(int cam, const SE3& T_b_c);
  void markReestimated(int cam);
  void setScale(ScaleStatus s);

  // A consumer's side: takes `newer` by value when its version differs from this one's. True when it did.
  bool follow(const RigState& newer) {
    if (newer.version_ == version_) return false;
    *this = newer;
    return true;
  }

 private:
  Rig rig_;
  std::vector<uint8_t> reestimated_;  // per camera
  ScaleStatus scale_;
  uint64_t version_ = 0;
};

}  // namespace mcslam
