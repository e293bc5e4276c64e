#include "mcslam/geometry/triangulation.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace mcslam {

const char* triangulationStatusName(TriangulationStatus s) {
  switch (s) {
    case TriangulationStatus::Ok: return "ok";
    case TriangulationStatus::TooFewRays: return "too_few_rays";
    case TriangulationStatus::Degenerate: return "degenerate";
    case TriangulationStatus::BehindCamera: return "behind_camera";
    case TriangulationStatus::LargeReprojection: return "large_reprojection";
    case TriangulationStatus::LowParallax: return "low_parallax";
    case TriangulationStatus::Uncertain: return "uncertain";
  }
  return "?";
}

bool triangulateLinear(const TriangulationObservation* obs, int n, Vec3& point) {
  if (n < 2) return false;
  Mat3 A = Mat3::Zero();
  Vec3 b = Vec3::Zero();
  for (int i = 0; i < n; ++i) {
    const Vec3 d = obs[i].T_f_c.R * obs[i].bearing;
    const Mat3 P = Mat3::Identity() - d * d.transpose();  // projects onto the plane normal to the ray
    A += P;
    b += P * obs[i].T_f_c.t;
  }
  Eigen::SelfAdjointEigenSolver<Mat3> eig;
  eig.computeDirect(A);
  // Parallel rays leave A with a (near) zero eigenvalue along the common direction.
  if (!(eig.eigenvalues()(0) > 1e-10 * std::max(1.0, eig.eigenvalues()(2)))) return false;
  point = eig.eigenvectors() * (eig.eigenvalues().cwiseInverse().asDiagonal() * (eig.eigenvectors().transpose() * b));
  return point.allFinite();
}

namespace {

// Gauss-Newton system of the whitened reprojection errors at `p`; false if a camera cannot see p.
bool buildSystem(const TriangulationObservation* obs, int n, const Vec3& p, Mat3& H, Vec3& g, double& cost,
                 double& max_err) {
  H.setZero();
  g.setZero();
  cost = 0;
  max_err = 0;
  for (int i = 0; i < n; ++i) {
    const SE3& T = obs[i].T_f_c;
    const Vec3 pc = T.R.transpose() * (p - T.t);
    Vec2 uv;
    Mat23 Jp;
    if (!obs[i].model->project(pc, uv, &Jp)) return false;
    const double inv_sigma = 1.0 / obs[i].sigma_px;
    const Vec2 r = (uv - obs[i].uv) * inv_sigma;
    const Mat23 J = inv_sigma * Jp * T.R.transpose();
    H += J.transpose() * J;
    g += J.transpose() * r;
    cost += r.squaredNorm();
    max_err = std::max(max_err, r.norm());
  }
  return true;
}

bool depthKnown(const TriangulationResult& r, const TriangulationOptions& o) {
  if (!(o.reference_inverse_depth > 0)) return r.relative_depth_sigma <= o.max_relative_depth_sigma;
  return r.inverse_depth_sigma <= o.max_relative_depth_sigma * o.reference_inverse_depth &&
         r.relative_depth_sigma <= 1.0;
}

}  // namespace

TriangulationResult triangulate(const TriangulationObservation* obs, int n, const TriangulationOptions& options) {
  TriangulationResult res;
  if (n < 2) return res;
  Vec3 p;
  if (!triangulateLinear(obs, n, p)) {
    res.status = TriangulationStatus::Degenerate;
    return res;
  }
  Mat3 H;
  Vec3 g;
  double cost = 0, max_err = 0;
  if (!buildSystem(obs, n, p, H, g, cost, max_err)) {
    res.status = TriangulationStatus::BehindCamera;
    return res;
  }
  double lambda = 1e-6;
  for (int it = 0; it < options.max_iterations; ++it) {
    Mat3 Hd = H;
    Hd.diagonal() *= 1.0 + lambda;
    const Vec3 step = -Hd.ldlt().solve(g);
    if (!step.allFinite()) break;
    const Vec3 pn = p + step;
    Mat3 Hn;
    Vec3 gn;
    double cn = 0, en = 0;
    if (buildSystem(obs, n, pn, Hn, gn, cn, en) && cn <= cost) {
      const bool small = step.norm() < 1e-9 * std::max(1.0, p.norm());
      p = pn;
      H = Hn;
      g = gn;
      cost = cn;
      max_err = en;
      lambda = std::max(1e-9, lambda * 0.1);
      if (small) break;
    } else {
      lambda *= 10.0;
      if (lambda > 1e6) break;
    }
  }
  res.point = p;
  res.max_error_sigmas = max_err;

  // Cheirality, parallax and depth uncertainty per observing camera.
  const Mat3 cov = H.ldlt().solve(Mat3::Identity());
  double max_cos = 1.0;
  for (int i = 0; i < n; ++i) {
    const Vec3 ray = p - obs[i].T_f_c.t;
    const double depth = (obs[i].T_f_c.R.transpose() * ray).z();
    const double range = ray.norm();
    const bool fisheye_side = obs[i].model->distortion() == Distortion::Equidistant;
    if (!(range > options.min_depth) || (!fisheye_side && !(depth > options.min_depth))) {
      res.status = TriangulationStatus::BehindCamera;
      return res;
    }
    const Vec3 u = ray / range;
    const double sigma = std::sqrt(std::max(0.0, u.dot(cov * u)));
    res.relative_depth_sigma = std::max(res.relative_depth_sigma, sigma / range);
    res.inverse_depth_sigma = std::max(res.inverse_depth_sigma, sigma / (range * range));
    for (int j = i + 1; j < n; ++j) {
      const Vec3 rj = (p - obs[j].T_f_c.t).normalized();
      max_cos = std::min(max_cos, u.dot(rj));
    }
  }
  res.max_parallax_deg = std::acos(std::clamp(max_cos, -1.0, 1.0)) * 180.0 / M_PI;
  if (max_err > options.max_reprojection_sigmas)
    res.status = TriangulationStatus::LargeReprojection;
  else if (res.max_parallax_deg < options.min_parallax_deg)
    res.status = TriangulationStatus::LowParallax;
  else if (!depthKnown(res, options))
    res.status = TriangulationStatus::Uncertain;
  else
    res.status = TriangulationStatus::Ok;
  return res;
}

}  // namespace mcslam
