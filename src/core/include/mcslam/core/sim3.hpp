#pragma once
// Similarity transforms: a rotation, a translation and a scale, p_a = s R p_b + t. The poses of a map whose unit
// is not metric (one camera; a rig without overlap before its scale is known) drift in scale as well, and a loop
// closes on such a map only as a similarity.
//
// Tangent vectors of Sim(3) are [rho; phi; sigma] (the SE(3) order, then the log of the scale); exp/log are the
// true group maps. Perturbations are on the right, S <- S * exp(delta), as for SE(3).
#include "mcslam/core/se3.hpp"

namespace mcslam {

using Vec7 = Eigen::Matrix<double, 7, 1>;
using Mat7 = Eigen::Matrix<double, 7, 7>;

// W(sigma, phi) = sum_k (sigma I + hat(phi))^k / (k + 1)!, the matrix that takes rho to the translation of
// exp([rho; phi; sigma]). Summed as a series: sigma I and hat(phi) commute, so no closed form with its cases
// (sigma or the angle near zero) is needed, and the residuals a pose graph meets are well inside the radius where
// thirty terms reach double precision.
inline Mat3 sim3TranslationJacobian(const Vec3& phi, double sigma) {
  const Mat3 X = sigma * Mat3::Identity() + hat(phi);
  Mat3 term = Mat3::Identity();
  Mat3 W = Mat3::Identity();
  for (int k = 1; k < 40; ++k) {
    term = term * X / static_cast<double>(k + 1);
    W += term;
    if (term.lpNorm<Eigen::Infinity>() < 1e-18) break;
  }
  return W;
}

struct Sim3 {
  Mat3 R = Mat3::Identity();
  Vec3 t = Vec3::Zero();
  double s = 1.0;

  Sim3() = default;
  Sim3(const Mat3& R_, const Vec3& t_, double s_) : R(R_), t(t_), s(s_) {}
  explicit Sim3(const SE3& T, double s_ = 1.0) : R(T.R), t(T.t), s(s_) {}

  static constexpr int kDof = 7;
  using Tangent = Vec7;
  using Jacobian = Mat7;

  SE3 rigid() const { return {R, t}; }  // the rotation and translation, without the scale

  Sim3 inverse() const {
    const Mat3 Rt = R.transpose();
    return {Rt, -(Rt * t) / s, 1.0 / s};
  }
  Sim3 operator*(const Sim3& o) const { return {R * o.R, s * (R * o.t) + t, s * o.s}; }
  Vec3 operator*(const Vec3& p) const { return s * (R * p) + t; }

  void normalize() { R = Eigen::Quaterniond(R).normalized().toRotationMatrix(); }

  static Sim3 exp(const Vec7& xi) {
    const Vec3 phi = xi.segment<3>(3);
    const double sigma = xi[6];
    return {so3Exp(phi), sim3TranslationJacobian(phi, sigma) * xi.head<3>(), std::exp(sigma)};
  }
  Vec7 log() const {
    Vec7 xi;
    const Vec3 phi = so3Log(R);
    const double sigma = std::log(s);
    xi.head<3>() = sim3TranslationJacobian(phi, sigma).partialPivLu().solve(t);
    xi.segment<3>(3) = phi;
    xi[6] = sigma;
    return xi;
  }

  // exp(Ad(S) xi) = S exp(xi) S^-1.
  Mat7 adjoint() const {
    Mat7 A = Mat7::Zero();
    A.topLeftCorner<3, 3>() = s * R;
    A.block<3, 3>(0, 3) = hat(t) * R;
    A.block<3, 1>(0, 6) = -t;
    A.block<3, 3>(3, 3) = R;
    A(6, 6) = 1.0;
    return A;
  }
  // ad(xi) zeta = [xi, zeta] of the Lie algebra.
  static Mat7 smallAdjoint(const Vec7& xi) {
    Mat7 ad = Mat7::Zero();
    const Vec3 rho = xi.head<3>();
    const Vec3 phi = xi.segment<3>(3);
    ad.topLeftCorner<3, 3>() = xi[6] * Mat3::Identity() + hat(phi);
    ad.block<3, 3>(0, 3) = hat(rho);
    ad.block<3, 1>(0, 6) = -rho;
    ad.block<3, 3>(3, 3) = hat(phi);
    return ad;
  }
};

}  // namespace mcslam
