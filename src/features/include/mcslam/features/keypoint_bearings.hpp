#pragma once
// Unit bearings of keypoints (camera frame): interpolated on a per-camera grid of unprojected pixels and polished
// by one Gauss-Newton step on the projection, instead of each lens model's iterative undistortion per keypoint.
// Depends on the intrinsics only; the grids are computed once, at construction.
#include <vector>

#include "mcslam/calib/rig.hpp"
#include "mcslam/features/frame_features.hpp"

namespace mcslam {

class KeypointBearings {
 public:
  explicit KeypointBearings(const Rig& rig);

  // The bearing of pixel uv of camera `cam` (whose model is rig.model(cam), the rig given at construction or
  // one with the same intrinsics). False where the model has none.
  bool bearingOf(const Rig& rig, int cam, const Vec2& uv, Vec3& bearing) const;
  // Every keypoint of `camera`: f.bearings and f.valid, and f.mv_of reset to -1 (in no multi-view feature yet).
  void compute(const Rig& rig, FrameFeatures& f, int camera) const;

 private:
  static constexpr int kGridStep = 8;
  std::vector<std::vector<Vec3>> grid_;  // per camera: bearings on a pixel grid (zero where the model has none)
  std::vector<int> cols_;                // per camera: grid columns
};

}  // namespace mcslam
