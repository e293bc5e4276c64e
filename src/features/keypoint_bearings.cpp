#include "mcslam/features/keypoint_bearings.hpp"

#include <cmath>
#include <cstddef>

namespace mcslam {

KeypointBearings::KeypointBearings(const Rig& rig) {
  for (int c = 0; c < rig.size(); ++c) {
    const CameraModel& model = rig.model(c);
    const int cols = model.width() / kGridStep + 2, rows = model.height() / kGridStep + 2;
    cols_.push_back(cols);
    grid_.emplace_back(static_cast<std::size_t>(cols) * rows, Vec3::Zero());
    for (int gy = 0; gy < rows; ++gy) {
      for (int gx = 0; gx < cols; ++gx) {
        Vec3 b;
        if (model.unproject(Vec2(gx * kGridStep, gy * kGridStep), b)) grid_[c][gy * cols + gx] = b;
      }
    }
  }
}

// Interpolated on the camera's grid and polished by one Gauss-Newton step on the projection (the smallest
// bearing change that moves its projection onto the pixel); the model's iterative unprojection where the grid
// has no bearing.
bool KeypointBearings::bearingOf(const Rig& rig, int cam, const Vec2& uv, Vec3& bearing) const {
  const CameraModel& model = rig.model(cam);
  const std::vector<Vec3>& grid = grid_[cam];
  const int cols = cols_[cam], rows = static_cast<int>(grid.size()) / cols;
  const double gxf = uv.x() / kGridStep, gyf = uv.y() / kGridStep;
  const int gx = static_cast<int>(std::floor(gxf)), gy = static_cast<int>(std::floor(gyf));
  if (gx >= 0 && gy >= 0 && gx + 1 < cols && gy + 1 < rows) {
    const Vec3& b00 = grid[gy * cols + gx];
    const Vec3& b10 = grid[gy * cols + gx + 1];
    const Vec3& b01 = grid[(gy + 1) * cols + gx];
    const Vec3& b11 = grid[(gy + 1) * cols + gx + 1];
    if (b00.squaredNorm() > 0 && b10.squaredNorm() > 0 && b01.squaredNorm() > 0 && b11.squaredNorm() > 0) {
      const double ax = gxf - gx, ay = gyf - gy;
      Vec3 b = ((1 - ax) * (1 - ay)) * b00 + (ax * (1 - ay)) * b10 + ((1 - ax) * ay) * b01 + (ax * ay) * b11;
      b.normalize();
      Vec2 proj;
      Mat23 J;
      if (model.project(b, proj, &J)) {
        const Mat2 JJt = J * J.transpose();
        const Vec3 delta = J.transpose() * JJt.inverse() * (uv - proj);
        if (delta.allFinite() && delta.norm() < 1e-2) {
          bearing = (b + delta).normalized();
          return true;
        }
      }
    }
  }
  return model.unproject(uv, bearing);
}

void KeypointBearings::compute(const Rig& rig, FrameFeatures& f, int c) const {
  const FeatureSet& s = f.sets[c];
  for (int k = 0; k < s.count; ++k) {
    const bool ok = bearingOf(rig, c, Vec2(s.keypoints[k].x, s.keypoints[k].y), f.bearings[c][k]);
    f.valid[c][k] = ok ? 1 : 0;
    f.mv_of[c][k] = -1;
  }
}

}  // namespace mcslam
