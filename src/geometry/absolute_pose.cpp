#include "mcslam/geometry/absolute_pose.hpp"

namespace mcslam {

RigProjector::RigProjector(const Rig& rig) {
  models_.reserve(rig.size());
  T_c_b_.reserve(rig.size());
  for (const RigCamera& cam : rig.cameras) {
    models_.push_back(cam.model);
    T_c_b_.push_back(cam.T_b_c.inverse());
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
