#include "mcslam/geometry/absolute_pose.hpp"

#include <algorithm>
#include <cmath>

namespace mcslam {

namespace {

// Largest angle between the bearings of neighbouring pixels over a grid of the image, with a
// margin for what the grid misses. Pixels whose bearing is undefined are skipped.
double maxRadiansPerPixel(const CameraModel& m) {
  constexpr int kSteps = 48;
  double worst = 0;
  for (int iy = 0; iy <= kSteps; ++iy) {
    for (int ix = 0; ix <= kSteps; ++ix) {
      const Vec2 uv((m.width() - 2) * ix / double(kSteps), (m.height() - 2) * iy / double(kSteps));
      Vec3 b, bx, by;
      if (!m.unproject(uv, b)) continue;
      if (m.unproject(uv + Vec2(1, 0), bx)) worst = std::max(worst, std::acos(std::min(1.0, b.dot(bx))));
      if (m.unproject(uv + Vec2(0, 1), by)) worst = std::max(worst, std::acos(std::min(1.0, b.dot(by))));
    }
  }
  return 1.5 * (worst > 0 ? worst : 1.0 / std::min(m.fx(), m.fy()));
}

}  // namespace

RigProjector::RigProjector(const Rig& rig) {
  models_.reserve(rig.size());
  T_c_b_.reserve(rig.size());
  max_rad_per_px_.reserve(rig.size());
  for (const RigCamera& cam : rig.cameras) {
    models_.push_back(cam.model);
    T_c_b_.push_back(cam.T_b_c.inverse());
    max_rad_per_px_.push_back(mcslam::maxRadiansPerPixel(cam.model));
  }
}

bool RigProjector::residual(const SE3& T_b_w, const PoseObservation& obs, Vec2& r, Mat26* J) const {
  if (obs.camera < 0 || obs.camera >= numCameras()) return false;
  const SE3& T_cb = T_c_b_[obs.camera];
  const Vec3 p_b = T_b_w * obs.point_w;
  const Vec3 p_c = T_cb * p_b;
  Vec2 uv;
  Mat23 Jp;
  if (!models_[obs.camera].project(p_c, uv, J ? &Jp : nullptr)) return false;
  r = uv - obs.pixel;
  if (J) {
    // T_b_w <- exp(-delta) T_b_w moves p_b by -rho + p_b x phi.
    const Mat23 JR = Jp * T_cb.R;
    J->leftCols<3>() = -JR;
    J->rightCols<3>() = JR * hat(p_b);
  }
  return true;
}

}  // namespace mcslam
