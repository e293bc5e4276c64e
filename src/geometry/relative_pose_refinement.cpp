#include "mcslam/geometry/relative_pose_refinement.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>

#include "mcslam/backend/levenberg_marquardt.hpp"

namespace mcslam::relative_pose_detail {

namespace {

using Row6 = Eigen::Matrix<double, 1, 6>;
// At most six parameters: dynamic sizes in fixed storage, so that nothing here allocates.
using MatUpTo6 = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
using VecUpTo6 = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;
using RowUpTo6 = Eigen::Matrix<double, 1, Eigen::Dynamic, Eigen::RowMajor, 1, 6>;

// Two unit vectors orthogonal to t (columns): the tangent of the unit sphere at t.
Eigen::Matrix<double, 3, 2> tangentBasis(const Vec3& t) {
  const Vec3 n = t.normalized();
  const Vec3 a = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  Eigen::Matrix<double, 3, 2> B;
  B.col(0) = n.cross(a).normalized();
  B.col(1) = n.cross(B.col(0));
  return B;
}

double huberLoss(double s, double k) { return s <= k * k ? s : 2.0 * k * std::sqrt(s) - k * k; }
double huberWeight(double s, double k) { return s <= k * k ? 1.0 : k / std::sqrt(s); }

double cost(std::span<const RayPair> matches, std::span<const uint8_t> mask, const SE3& T, double k) {
  double c = 0;
  for (size_t i = 0; i < matches.size(); ++i) {
    if (!mask[i]) continue;
    const double e = sampsonError(matches[i], T);
    c += huberLoss(e * e, k);
  }
  return c;
}

// Parameters of the solved pose: with a fixed scale, t moves on its sphere (2 parameters).
SE3 applyStep(const SE3& T, const VecUpTo6& step, bool fixed_scale, const Eigen::Matrix<double, 3, 2>& B) {
  SE3 out = T;
  if (fixed_scale) {
    out.t = (T.t + B * step.head<2>()).normalized() * T.t.norm();
    out.R = T.R * so3Exp(step.tail<3>());
  } else {
    out.t = T.t + step.head<3>();
    out.R = T.R * so3Exp(step.tail<3>());
  }
  return out;
}

// The match with its bearings moved (first order, to convergence) onto the model T: the Jacobian
// for the information matrix must not contain the measurement noise, or the noise itself looks
// like information about weakly observed directions (the metric scale above all).
RayPair consistentRays(const RayPair& m, const SE3& T) {
  RayPair c = m;
  for (int it = 0; it < 5; ++it) {
    const Vec3 t = T.t;
    const Mat3& R = T.R;
    const Vec3 m1 = c.c1.cross(c.d1);
    const Vec3 Rd2 = R * c.d2;
    const Vec3 Rm2 = R * c.c2.cross(c.d2);
    const double e = c.d1.dot(t.cross(Rd2) + Rm2) + m1.dot(Rd2);
    Vec3 g1 = Rm2 + t.cross(Rd2) + Rd2.cross(c.c1);
    Vec3 g2 = (R.transpose() * c.d1).cross(c.c2) + R.transpose() * (c.d1.cross(t)) + R.transpose() * m1;
    g1 -= g1.dot(c.d1) * c.d1;
    g2 -= g2.dot(c.d2) * c.d2;
    const double s2 = g1.squaredNorm() + g2.squaredNorm();
    if (!(s2 > 1e-24)) break;
    c.d1 = (c.d1 - (e / s2) * g1).normalized();
    c.d2 = (c.d2 - (e / s2) * g2).normalized();
    if (std::abs(e) < 1e-15) break;
  }
  return c;
}

// Levenberg-Marquardt with Huber loss over the masked matches; with a fixed scale, t moves on its sphere.
class RelativePoseProblem final : public backend::LeastSquaresProblem {
 public:
  RelativePoseProblem(std::span<const RayPair> matches, std::span<const uint8_t> mask, SE3& T, bool central,
                      double huber)
      : matches_(matches), mask_(mask), T_(T), central_(central), dim_(central ? 5 : 6), k_(huber) {
    c_ = relative_pose_detail::cost(matches_, mask_, T_, k_);
  }
  bool linearize() override {
    B_ = tangentBasis(T_.t);
    H_ = MatUpTo6::Zero(dim_, dim_);
    g_ = VecUpTo6::Zero(dim_);
    for (size_t i = 0; i < matches_.size(); ++i) {
      if (!mask_[i]) continue;
      // The whole derivative: away from the optimum the one with the normalization held is not a descent
      // direction and LM stalls.
      Row6 J6;
      const double e = sampsonError(matches_[i], T_, nullptr, &J6);
      RowUpTo6 J(dim_);
      if (central_) {
        J << J6.leftCols<3>() * B_, J6.rightCols<3>();
      } else {
        J = J6;
      }
      const double w = huberWeight(e * e, k_);
      H_.noalias() += w * J.transpose() * J;
      g_.noalias() += w * J.transpose() * e;
    }
    return true;
  }
  double cost() const override { return c_; }
  void buildDampedSystem(double mu) override { backend::dampedMatrix(H_, mu, A_); }
  bool solveStep() override {
    step_ = A_.ldlt().solve(-g_);
    return step_.allFinite();
  }
  double stepNorm() const override { return step_.norm(); }
  double modelCostDecrease(double) const override { return -(g_.dot(step_) + 0.5 * step_.dot(H_ * step_)); }
  bool evaluateTrial(double& cost) override {
    candidate_ = applyStep(T_, step_, central_, B_);
    cost = trial_cost_ = relative_pose_detail::cost(matches_, mask_, candidate_, k_);
    return true;
  }
  void acceptTrial() override {
    T_ = candidate_;
    c_ = trial_cost_;
  }

 private:
  std::span<const RayPair> matches_;
  std::span<const uint8_t> mask_;
  SE3& T_;
  const bool central_;
  const int dim_;
  const double k_;
  double c_ = 0, trial_cost_ = 0;
  Eigen::Matrix<double, 3, 2> B_;
  MatUpTo6 H_, A_;
  VecUpTo6 g_, step_;
  SE3 candidate_;
};

}  // namespace

namespace {

// kCentral: both centres are zero (one camera's rays), and the terms they enter are left out: they are exact
// zeros, so both forms give the same values, the central one with fewer operations.
template <bool kCentral>
double sampsonErrorOf(const RayPair& m, const SE3& T_1_2, Eigen::Matrix<double, 1, 6>* J,
                      Eigen::Matrix<double, 1, 6>* J_full) {
  const Mat3& R = T_1_2.R;
  const Vec3& t = T_1_2.t;
  const Vec3 Rd2 = R * m.d2;
  // Line 2 in frame 1 has direction R d2 and moment R m2 + t x R d2; lines meet when d1.m2' + d2'.m1 = 0.
  Vec3 m1 = Vec3::Zero(), m2 = Vec3::Zero();
  double e;
  Vec3 g1;
  if constexpr (kCentral) {
    g1 = t.cross(Rd2);
    e = m.d1.dot(g1);
  } else {
    m1 = m.c1.cross(m.d1);
    m2 = m.c2.cross(m.d2);
    const Vec3 Rm2 = R * m2;
    e = m.d1.dot(t.cross(Rd2) + Rm2) + m1.dot(Rd2);
    g1 = Rm2 + t.cross(Rd2) + Rd2.cross(m.c1);
  }
  // Derivatives of e with respect to each bearing (the moments move with them), projected on the
  // plane where bearing noise lives.
  const Vec3 Rt_d1 = R.transpose() * m.d1;
  const Vec3 Rt_d1_x_t = R.transpose() * (m.d1.cross(t));
  Vec3 g2, Rt_m1 = Vec3::Zero();
  if constexpr (kCentral) {
    g2 = Rt_d1_x_t;
  } else {
    Rt_m1 = R.transpose() * m1;
    g2 = Rt_d1.cross(m.c2) + Rt_d1_x_t + Rt_m1;
  }
  const Vec3 h1 = g1 - g1.dot(m.d1) * m.d1, h2 = g2 - g2.dot(m.d2) * m.d2;
  const double s2 = h1.squaredNorm() + h2.squaredNorm();
  const double s = std::sqrt(std::max(s2, 1e-24));
  if (!J && !J_full) return e / s;
  Eigen::Matrix<double, 1, 6> de;
  de.leftCols<3>() = Rd2.cross(m.d1).transpose();
  Vec3 dphi = Rt_d1_x_t.cross(m.d2);
  if constexpr (!kCentral) {
    dphi += Rt_d1.cross(m2);  // in the general form's order of sums: the same rounding
    dphi += Rt_m1.cross(m.d2);
  }
  de.rightCols<3>() = -dphi.transpose();
  if (J) *J = de / s;
  if (J_full) {
    // d(e / s) = de / s - e ds / s^2, with s ds = h1 . dg1 + h2 . dg2 (h = the projected g), for t + dt and
    // R exp(phi): R v moves by R (phi x v), R^T v by (R^T v) x phi.
    Eigen::Matrix<double, 1, 6> s_ds = Eigen::Matrix<double, 1, 6>::Zero();
    if (s2 > 1e-24) {
      s_ds.leftCols<3>() = (Rd2.cross(h1) + (R * h2).cross(m.d1)).transpose();
      Vec3 ds_phi;
      if constexpr (kCentral) {
        ds_phi = m.d2.cross(R.transpose() * (h1.cross(t))) + h2.cross(Rt_d1_x_t);
      } else {
        ds_phi = m2.cross(R.transpose() * h1) + m.d2.cross(R.transpose() * (h1.cross(t))) +
                 m.d2.cross(R.transpose() * m.c1.cross(h1)) + m.c2.cross(h2).cross(Rt_d1) + h2.cross(Rt_d1_x_t + Rt_m1);
      }
      s_ds.rightCols<3>() = ds_phi.transpose();
    }
    *J_full = de / s - (e / (s * s * s)) * s_ds;
  }
  return e / s;
}

}  // namespace

double sampsonError(const RayPair& m, const SE3& T_1_2, Eigen::Matrix<double, 1, 6>* J,
                    Eigen::Matrix<double, 1, 6>* J_full) {
  const bool central = m.c1.isZero(0) && m.c2.isZero(0);
  return central ? sampsonErrorOf<true>(m, T_1_2, J, J_full) : sampsonErrorOf<false>(m, T_1_2, J, J_full);
}

SE3 refineRelativePose(std::span<const RayPair> matches, std::span<const uint8_t> mask, const SE3& start,
                       bool fixed_scale, const RelativePoseOptions& options) {
  SE3 T = start;
  if (!(T.t.norm() > 0)) return T;
  RelativePoseProblem problem(matches, mask, T, fixed_scale, 2.0 * options.bearing_sigma_rad);
  backend::LoopOptions loop;
  loop.damping = backend::DampingPolicy::trustRegion(1e4);
  loop.max_steps = 100;
  loop.small_step = backend::LoopOptions::SmallStep::EndsOnceTaken;
  loop.min_step_norm = 1e-12;
  // Where the motion is small the cost is nearly flat along the translation's direction and Gauss-Newton converges
  // only linearly: the steps after this change the pose by far less than the bearings' noise.
  loop.function_tolerance = 1e-8;
  loop.stop_on_failed_solve = true;
  backend::minimize(problem, loop);
  T.normalize();
  return T;
}

bool isInlier(const RayPair& m, const SE3& T, double max_angle_rad) {
  if (!(std::abs(sampsonError(m, T)) < max_angle_rad)) return false;
  // Midpoint triangulation in frame 1: both depths must be positive, unless the rays are too close to parallel
  // for the sign to mean anything.
  const Vec3 d2 = T.R * m.d2;
  const Vec3 w = T.R * m.c2 + T.t - m.c1;
  const double b = m.d1.dot(d2);
  if (1.0 - b * b > 4.0 * max_angle_rad * max_angle_rad) {
    const double l2 = (d2.dot(w) - b * m.d1.dot(w)) / (b * b - 1.0);
    const double l1 = m.d1.dot(w) + b * l2;
    if (!(l1 > 0 && l2 > 0)) return false;
  }
  return true;
}

int selectInliers(std::span<const RayPair> matches, const SE3& T, double max_angle_rad, std::span<uint8_t> mask) {
  int count = 0;
  for (size_t i = 0; i < matches.size(); ++i) {
    mask[i] = isInlier(matches[i], T, max_angle_rad) ? 1 : 0;
    count += mask[i];
  }
  return count;
}

int countInliers(std::span<const RayPair> matches, const SE3& T, double max_angle_rad) {
  int count = 0;
  for (const RayPair& m : matches) count += isInlier(m, T, max_angle_rad) ? 1 : 0;
  return count;
}

Observability analyzeObservability(std::span<const RayPair> matches, std::span<const uint8_t> mask, const SE3& T,
                                   bool central, double bearing_sigma_rad, std::span<double> scratch) {
  Observability out;
  Mat6 H = Mat6::Zero();
  std::size_t parallax_count = 0;
  const double inv_var = 1.0 / (bearing_sigma_rad * bearing_sigma_rad);
  for (size_t i = 0; i < matches.size(); ++i) {
    if (!mask[i]) continue;
    Row6 J;
    sampsonError(consistentRays(matches[i], T), T, &J);
    H.noalias() += inv_var * J.transpose() * J;
    const Vec3 d2 = T.R * matches[i].d2;
    scratch[parallax_count++] = std::atan2(matches[i].d1.cross(d2).norm(), matches[i].d1.dot(d2));
  }
  if (parallax_count > 0) {
    const auto parallax = scratch.first(parallax_count);
    std::nth_element(parallax.begin(), parallax.begin() + parallax.size() / 2, parallax.end());
    out.median_parallax_rad = parallax[parallax.size() / 2];
  }
  const double tn = T.t.norm();
  if (!(tn > 1e-12)) return out;
  // Basis [t direction | two directions orthogonal to t | rotation]: the first coordinate is the
  // metric scale, the next two the translation direction.
  Mat6 Q = Mat6::Zero();
  Q.block<3, 1>(0, 0) = T.t / tn;
  Q.block<3, 2>(0, 1) = tangentBasis(T.t);
  Q.bottomRightCorner<3, 3>().setIdentity();
  const Mat6 Hq = Q.transpose() * H * Q;
  // Marginal information of a block = its Schur complement: the other parameters are free.
  // A (numerically) singular remainder means that block is not observable either: infinite sigma.
  auto marginalCovariance = [](const MatUpTo6& Hm, int first, int size, MatUpTo6& cov) {
    const int n = static_cast<int>(Hm.rows());
    std::array<int, 6> keep{}, rest{};
    int kept = 0, others = 0;
    for (int i = 0; i < n; ++i) (i >= first && i < first + size ? keep[kept++] : rest[others++]) = i;
    MatUpTo6 Hkk(size, size), Hkr(size, n - size), Hrr(n - size, n - size);
    for (int a = 0; a < size; ++a) {
      for (int b = 0; b < size; ++b) Hkk(a, b) = Hm(keep[a], keep[b]);
      for (int b = 0; b < n - size; ++b) Hkr(a, b) = Hm(keep[a], rest[b]);
    }
    for (int a = 0; a < n - size; ++a)
      for (int b = 0; b < n - size; ++b) Hrr(a, b) = Hm(rest[a], rest[b]);
    Eigen::SelfAdjointEigenSolver<MatUpTo6> er(Hrr);
    const double max_ev = std::max(er.eigenvalues().maxCoeff(), Hkk.diagonal().maxCoeff());
    if (!(er.eigenvalues().minCoeff() > 1e-10 * max_ev)) return false;
    const MatUpTo6 S = Hkk - Hkr * er.eigenvectors() * er.eigenvalues().cwiseInverse().asDiagonal() *
                                 er.eigenvectors().transpose() * Hkr.transpose();
    Eigen::SelfAdjointEigenSolver<MatUpTo6> es(S);
    if (!(es.eigenvalues().minCoeff() > 1e-10 * max_ev)) return false;
    cov = es.eigenvectors() * es.eigenvalues().cwiseInverse().asDiagonal() * es.eigenvectors().transpose();
    return true;
  };
  MatUpTo6 cov;
  if (central) {
    // Unit translation: only the direction and the rotation are parameters.
    const MatUpTo6 H5 = Hq.bottomRightCorner<5, 5>();
    if (marginalCovariance(H5, 0, 2, cov)) {
      out.direction_sigma_rad = std::sqrt(Eigen::SelfAdjointEigenSolver<MatUpTo6>(cov).eigenvalues().maxCoeff());
    }
    return out;
  }
  const MatUpTo6 H6 = Hq;
  if (marginalCovariance(H6, 0, 1, cov)) out.relative_scale_sigma = std::sqrt(cov(0, 0)) / tn;
  if (marginalCovariance(H6, 1, 2, cov)) {
    out.direction_sigma_rad = std::sqrt(Eigen::SelfAdjointEigenSolver<MatUpTo6>(cov).eigenvalues().maxCoeff()) / tn;
  }
  return out;
}

}  // namespace mcslam::relative_pose_detail
