#pragma once
// Reprojection residual of the paper's eq. 7 through body pose, extrinsic and the full camera
// model (distortion included), with analytic Jacobians.
//
//   p_c = T_b_c^-1 * T_w_b^-1 * p_w,   r = (project(p_c) - uv) / sigma
//
// Jacobians are for right perturbations T_w_b * exp(d), T_b_c * exp(e) ([rho; phi] order) and an
// additive perturbation of the world point.
#include "mcslam/calib/camera_model.hpp"
#include "mcslam/core/se3.hpp"

namespace mcslam::backend {

struct ReprojectionJacobians {
  Mat26 pose;       // d r / d(T_w_b)
  Mat26 extrinsic;  // d r / d(T_b_c)
  Mat23 point;      // d r / d(p_w)
};

// Fast form with the inverse transforms precomputed once per keyframe (T_b_w) and camera (T_c_b).
// False when the point does not project (behind the camera, outside the model's domain).
inline bool reprojectionResidualInverse(const CameraModel& camera, const SE3& T_b_w, const SE3& T_c_b, const Vec3& p_w,
                                        const Vec2& uv, double inv_sigma, Vec2& r, ReprojectionJacobians* J) {
  const Vec3 p_b = T_b_w * p_w;
  const Vec3 p_c = T_c_b * p_b;
  Vec2 predicted(0.0, 0.0);  // project() sets it; initialised for the compiler
  Mat23 J_proj;
  if (!camera.project(p_c, predicted, J ? &J_proj : nullptr)) return false;
  r = (predicted - uv) * inv_sigma;
  if (J) {
    // exp(-e) p ~= p - rho + [p]x phi for both the body and the camera perturbation.
    const Mat23 A = inv_sigma * J_proj;
    J->extrinsic.leftCols<3>() = -A;
    J->extrinsic.rightCols<3>().noalias() = A * hat(p_c);
    const Mat23 B = A * T_c_b.R;
    J->pose.leftCols<3>() = -B;
    J->pose.rightCols<3>().noalias() = B * hat(p_b);
    J->point.noalias() = B * T_b_w.R;
  }
  return true;
}

inline bool reprojectionResidual(const CameraModel& camera, const SE3& T_w_b, const SE3& T_b_c, const Vec3& p_w,
                                 const Vec2& uv, double sigma, Vec2& r, ReprojectionJacobians* J = nullptr) {
  return reprojectionResidualInverse(camera, T_w_b.inverse(), T_b_c.inverse(), p_w, uv, 1.0 / sigma, r, J);
}

}  // namespace mcslam::backend
