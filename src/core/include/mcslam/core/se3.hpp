#pragma once
// Rigid transforms and rotations, kept small and allocation-free.
//
// Conventions used across mcslam:
//  - T_a_b maps a point from frame b into frame a: p_a = T_a_b * p_b (Kalibr/Basalt naming).
//    The body pose in the world is T_w_b, a camera extrinsic is T_b_c.
//  - Tangent vectors of SE(3) are [rho; phi]: translation part first, rotation part last
//    (Sophus order). exp/log are the true SE(3) maps (with the left Jacobian V).
//  - Optimizers perturb on the right, T <- T * exp(delta), unless a module says otherwise.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace mcslam {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat2 = Eigen::Matrix2d;
using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat23 = Eigen::Matrix<double, 2, 3>;
using Mat26 = Eigen::Matrix<double, 2, 6>;
using Mat36 = Eigen::Matrix<double, 3, 6>;

inline Mat3 hat(const Vec3& v) {
  Mat3 m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// Rodrigues: rotation vector -> rotation matrix.
inline Mat3 so3Exp(const Vec3& w) {
  const double th2 = w.squaredNorm();
  const Mat3 W = hat(w);
  if (th2 < 1e-16) return Mat3::Identity() + W + 0.5 * W * W;
  const double th = std::sqrt(th2);
  return Mat3::Identity() + (std::sin(th) / th) * W + ((1.0 - std::cos(th)) / th2) * W * W;
}

// Rotation matrix -> rotation vector, stable near 0 and near pi.
inline Vec3 so3Log(const Mat3& R) {
  const Eigen::AngleAxisd aa(Eigen::Quaterniond(R).normalized());
  double angle = aa.angle();
  Vec3 axis = aa.axis();
  if (angle > M_PI) {  // keep the angle in [0, pi]
    angle = 2.0 * M_PI - angle;
    axis = -axis;
  }
  return axis * angle;
}

// Right Jacobian of SO(3): exp(w + dw) ~= exp(w) exp(Jr(w) dw).
inline Mat3 so3RightJacobian(const Vec3& w) {
  const double th2 = w.squaredNorm();
  const Mat3 W = hat(w);
  if (th2 < 1e-12) return Mat3::Identity() - 0.5 * W + W * W / 6.0;
  const double th = std::sqrt(th2);
  return Mat3::Identity() - ((1.0 - std::cos(th)) / th2) * W + ((th - std::sin(th)) / (th2 * th)) * W * W;
}

// Left Jacobian of SO(3) (the V matrix of SE(3) exp): Jl(w) = Jr(-w).
inline Mat3 so3LeftJacobian(const Vec3& w) { return so3RightJacobian(-w); }

inline Mat3 so3LeftJacobianInverse(const Vec3& w) {
  const double th2 = w.squaredNorm();
  const Mat3 W = hat(w);
  if (th2 < 1e-12) return Mat3::Identity() - 0.5 * W + W * W / 12.0;
  const double th = std::sqrt(th2);
  const double c = (1.0 / th2) * (1.0 - (th * std::sin(th)) / (2.0 * (1.0 - std::cos(th))));
  return Mat3::Identity() - 0.5 * W + c * W * W;
}

// Rigid transform with an orthonormal rotation matrix. Value type, no heap.
struct SE3 {
  Mat3 R = Mat3::Identity();
  Vec3 t = Vec3::Zero();

  SE3() = default;
  SE3(const Mat3& R_, const Vec3& t_) : R(R_), t(t_) {}
  SE3(const Eigen::Quaterniond& q, const Vec3& t_) : R(q.normalized().toRotationMatrix()), t(t_) {}

  static constexpr int kDof = 6;
  using Tangent = Vec6;
  using Jacobian = Mat6;

  static SE3 identity() { return {}; }
  static SE3 fromMatrix(const Mat4& T) { return {T.topLeftCorner<3, 3>(), T.topRightCorner<3, 1>()}; }

  Mat4 matrix() const {
    Mat4 T = Mat4::Identity();
    T.topLeftCorner<3, 3>() = R;
    T.topRightCorner<3, 1>() = t;
    return T;
  }
  Eigen::Quaterniond quaternion() const { return Eigen::Quaterniond(R).normalized(); }

  SE3 inverse() const { return {R.transpose(), -(R.transpose() * t)}; }
  SE3 operator*(const SE3& o) const { return {R * o.R, R * o.t + t}; }
  Vec3 operator*(const Vec3& p) const { return R * p + t; }

  // Re-orthonormalize R after many compositions.
  void normalize() { R = Eigen::Quaterniond(R).normalized().toRotationMatrix(); }

  // Tangent [rho; phi] -> SE(3).
  static SE3 exp(const Vec6& xi) {
    const Vec3 phi = xi.tail<3>();
    return {so3Exp(phi), so3LeftJacobian(phi) * xi.head<3>()};
  }
  Vec6 log() const {
    Vec6 xi;
    const Vec3 phi = so3Log(R);
    xi.head<3>() = so3LeftJacobianInverse(phi) * t;
    xi.tail<3>() = phi;
    return xi;
  }

  // Adjoint: exp(Ad(T) xi) = T exp(xi) T^-1, for [rho; phi] ordering.
  Mat6 adjoint() const {
    Mat6 A = Mat6::Zero();
    A.topLeftCorner<3, 3>() = R;
    A.topRightCorner<3, 3>() = hat(t) * R;
    A.bottomRightCorner<3, 3>() = R;
    return A;
  }
  // ad(xi) zeta = [xi, zeta] of the Lie algebra: [hat(phi) hat(rho); 0 hat(phi)].
  static Mat6 smallAdjoint(const Vec6& xi) {
    Mat6 ad = Mat6::Zero();
    ad.topLeftCorner<3, 3>() = hat(xi.tail<3>());
    ad.topRightCorner<3, 3>() = hat(xi.head<3>());
    ad.bottomRightCorner<3, 3>() = hat(xi.tail<3>());
    return ad;
  }
};

// Geodesic rotation angle between two rotations, radians.
inline double rotationAngle(const Mat3& Ra, const Mat3& Rb) { return so3Log(Ra.transpose() * Rb).norm(); }

}  // namespace mcslam
