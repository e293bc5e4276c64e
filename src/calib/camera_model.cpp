#include "mcslam/calib/camera_model.hpp"

#include <algorithm>
#include <cmath>

namespace mcslam {

namespace {
constexpr double kMinDepth = 1e-9;
// A pinhole without distortion is valid up to ~89.94 degrees; nothing useful lies beyond.
constexpr double kPinholeMaxRadius2 = 1e6;
// Equidistant lenses are valid up to the first turning point of theta_d(theta), capped here.
constexpr double kFisheyeMaxAngle = 170.0 * M_PI / 180.0;
}  // namespace

const char* distortionName(Distortion d) {
  switch (d) {
    case Distortion::None: return "none";
    case Distortion::RadTan: return "radtan";
    case Distortion::Equidistant: return "equidistant";
  }
  return "?";
}

CameraModel::CameraModel(int width, int height, double fx, double fy, double cx, double cy, Distortion distortion,
                         const std::array<double, 4>& coeffs)
    : width_(width), height_(height), fx_(fx), fy_(fy), cx_(cx), cy_(cy), distortion_(distortion), k_(coeffs) {
  if (distortion_ == Distortion::None) k_ = {0, 0, 0, 0};
  computeValidDomain();
}

void CameraModel::computeValidDomain() {
  if (distortion_ == Distortion::Equidistant) {
    // First theta where d(theta_d)/d(theta) stops being positive.
    max_angle_ = kFisheyeMaxAngle;
    constexpr int kSteps = 2000;
    for (int i = 1; i <= kSteps; ++i) {
      const double th = kFisheyeMaxAngle * i / kSteps;
      const double t2 = th * th;
      const double d = 1 + t2 * (3 * k_[0] + t2 * (5 * k_[1] + t2 * (7 * k_[2] + t2 * 9 * k_[3])));
      if (d <= 0.0) {
        max_angle_ = kFisheyeMaxAngle * (i - 1) / kSteps;
        break;
      }
    }
    max_radius2_ = 0;  // unused
    return;
  }
  max_radius2_ = kPinholeMaxRadius2;
  if (distortion_ == Distortion::RadTan) {
    // Radial part r(1 + k1 r^2 + k2 r^4) is monotonic while 1 + 3 k1 s + 5 k2 s^2 > 0, s = r^2.
    const double a = 5 * k_[1], b = 3 * k_[0], c = 1.0;
    double s_limit = kPinholeMaxRadius2;
    if (std::abs(a) < 1e-15) {
      if (b < 0) s_limit = -c / b;
    } else {
      const double disc = b * b - 4 * a * c;
      if (disc >= 0) {
        const double sq = std::sqrt(disc);
        for (double s : {(-b - sq) / (2 * a), (-b + sq) / (2 * a)}) {
          if (s > 0) s_limit = std::min(s_limit, s);
        }
      }
    }
    max_radius2_ = std::min(kPinholeMaxRadius2, 0.98 * s_limit);
    // Beyond the image the polynomial was never calibrated and grows wildly: keep the domain to twice
    // the radius the image corners reach.
    double corner_r2 = 0;
    for (const Vec2& corner :
         {Vec2(-0.5, -0.5), Vec2(width_ - 0.5, -0.5), Vec2(-0.5, height_ - 0.5), Vec2(width_ - 0.5, height_ - 0.5)}) {
      Vec3 ray;
      if (unproject(corner, ray) && ray.z() > 0)
        corner_r2 = std::max(corner_r2, ray.head<2>().squaredNorm() / (ray.z() * ray.z()));
    }
    if (corner_r2 > 0) max_radius2_ = std::min(max_radius2_, 4.0 * corner_r2);
  }
  max_angle_ = std::atan(std::sqrt(max_radius2_));
}

Vec2 CameraModel::distortNormalized(const Vec2& xy, Mat2* J) const {
  const double x = xy.x(), y = xy.y();
  const double r2 = x * x + y * y;
  switch (distortion_) {
    case Distortion::None:
      if (J) J->setIdentity();
      return xy;
    case Distortion::RadTan: {
      const double k1 = k_[0], k2 = k_[1], p1 = k_[2], p2 = k_[3];
      const double radial = 1 + r2 * (k1 + k2 * r2);
      const Vec2 d(x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
                   y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y);
      if (J) {
        const double dr = 2 * (k1 + 2 * k2 * r2);  // d(radial)/d(x) = dr * x
        (*J)(0, 0) = radial + x * dr * x + 2 * p1 * y + 6 * p2 * x;
        (*J)(0, 1) = x * dr * y + 2 * p1 * x + 2 * p2 * y;
        (*J)(1, 0) = y * dr * x + 2 * p1 * x + 2 * p2 * y;
        (*J)(1, 1) = radial + y * dr * y + 6 * p1 * y + 2 * p2 * x;
      }
      return d;
    }
    case Distortion::Equidistant: {
      const double r = std::sqrt(r2);
      const double th = std::atan(r);
      const double t2 = th * th;
      const double thd = th * (1 + t2 * (k_[0] + t2 * (k_[1] + t2 * (k_[2] + t2 * k_[3]))));
      if (r < 1e-12) {
        if (J) J->setIdentity();
        return xy;
      }
      const double s = thd / r;
      if (J) {
        const double dthd = 1 + t2 * (3 * k_[0] + t2 * (5 * k_[1] + t2 * (7 * k_[2] + t2 * 9 * k_[3])));
        const double ds_dr = (dthd / (1 + r2) * r - thd) / r2;  // d(s)/d(r)
        (*J)(0, 0) = s + ds_dr * x * x / r;
        (*J)(0, 1) = ds_dr * x * y / r;
        (*J)(1, 0) = ds_dr * x * y / r;
        (*J)(1, 1) = s + ds_dr * y * y / r;
      }
      return {s * x, s * y};
    }
  }
  return xy;
}

bool CameraModel::project(const Vec3& p, Vec2& uv, Mat23* J) const {
  if (distortion_ == Distortion::Equidistant) {
    const double X = p.x(), Y = p.y(), Z = p.z();
    const double rxy2 = X * X + Y * Y;
    const double rxy = std::sqrt(rxy2);
    const double th = std::atan2(rxy, Z);
    if (!(th <= max_angle_) || p.squaredNorm() < kMinDepth * kMinDepth) return false;
    const double t2 = th * th;
    const double poly = 1 + t2 * (k_[0] + t2 * (k_[1] + t2 * (k_[2] + t2 * k_[3])));
    const double thd = th * poly;
    if (rxy < 1e-12 * std::abs(Z)) {  // on the optical axis: the pinhole limit
      uv = Vec2(fx_ * X / Z + cx_, fy_ * Y / Z + cy_);
      if (J) {
        *J << fx_ / Z, 0, -fx_ * X / (Z * Z), 0, fy_ / Z, -fy_ * Y / (Z * Z);
      }
      return true;
    }
    const double s = thd / rxy;
    uv = Vec2(fx_ * s * X + cx_, fy_ * s * Y + cy_);
    if (J) {
      const double n2 = rxy2 + Z * Z;
      const double dthd = 1 + t2 * (3 * k_[0] + t2 * (5 * k_[1] + t2 * (7 * k_[2] + t2 * 9 * k_[3])));
      // d(theta)/d(X,Y,Z) and d(rxy)/d(X,Y,Z)
      const Vec3 dth(Z * X / (rxy * n2), Z * Y / (rxy * n2), -rxy / n2);
      const Vec3 drxy(X / rxy, Y / rxy, 0.0);
      const Vec3 ds = (dthd * dth * rxy - thd * drxy) / rxy2;
      Mat23 Jd;
      Jd.row(0) = X * ds.transpose();
      Jd.row(1) = Y * ds.transpose();
      Jd(0, 0) += s;
      Jd(1, 1) += s;
      J->row(0) = fx_ * Jd.row(0);
      J->row(1) = fy_ * Jd.row(1);
    }
    return true;
  }

  const double Z = p.z();
  if (!(Z > kMinDepth)) return false;
  const double iz = 1.0 / Z;
  const Vec2 xy(p.x() * iz, p.y() * iz);
  if (xy.squaredNorm() > max_radius2_) return false;
  Mat2 Jd;
  const Vec2 d = distortNormalized(xy, J ? &Jd : nullptr);
  uv = Vec2(fx_ * d.x() + cx_, fy_ * d.y() + cy_);
  if (J) {
    Mat23 Jn;
    Jn << iz, 0, -xy.x() * iz, 0, iz, -xy.y() * iz;
    const Mat23 Jdn = Jd * Jn;
    J->row(0) = fx_ * Jdn.row(0);
    J->row(1) = fy_ * Jdn.row(1);
  }
  return true;
}

bool CameraModel::unproject(const Vec2& uv, Vec3& bearing) const {
  const Vec2 xd((uv.x() - cx_) / fx_, (uv.y() - cy_) / fy_);
  if (distortion_ == Distortion::Equidistant) {
    const double thd = xd.norm();
    if (thd < 1e-14) {
      bearing = Vec3(xd.x(), xd.y(), 1.0).normalized();
      return true;
    }
    // Newton on theta * poly(theta) = theta_d, starting from theta_d.
    double th = std::min(thd, max_angle_);
    bool converged = false;
    for (int it = 0; it < 30; ++it) {
      const double t2 = th * th;
      const double f = th * (1 + t2 * (k_[0] + t2 * (k_[1] + t2 * (k_[2] + t2 * k_[3])))) - thd;
      const double df = 1 + t2 * (3 * k_[0] + t2 * (5 * k_[1] + t2 * (7 * k_[2] + t2 * 9 * k_[3])));
      if (!(df > 0)) return false;
      const double step = f / df;
      th = std::clamp(th - step, 0.0, max_angle_);
      if (std::abs(step) < 1e-15) {
        converged = true;
        break;
      }
    }
    if (!converged || th >= max_angle_) return false;
    const double st = std::sin(th) / thd;
    bearing = Vec3(st * xd.x(), st * xd.y(), std::cos(th));
    return true;
  }

  // Radtan / none: damped Newton on distort(x) = xd, starting from xd.
  Vec2 x = xd;
  if (distortion_ != Distortion::None) {
    Mat2 J;
    Vec2 r = distortNormalized(x, &J) - xd;
    double err = r.squaredNorm();
    bool converged = err < 1e-26;
    for (int it = 0; it < 50 && !converged; ++it) {
      const Vec2 step = J.partialPivLu().solve(r);
      double scale = 1.0;
      Vec2 xn;
      Vec2 rn;
      Mat2 Jn;
      double errn = 0;
      for (int ls = 0; ls < 20; ++ls, scale *= 0.5) {  // halve the step until the error falls
        xn = x - scale * step;
        rn = distortNormalized(xn, &Jn) - xd;
        errn = rn.squaredNorm();
        if (errn < err) break;
      }
      if (!(errn < err)) break;
      x = xn;
      r = rn;
      J = Jn;
      converged = errn < 1e-26 || (scale * step).squaredNorm() < 1e-30;
      err = errn;
    }
    if (!(err < 1e-20)) return false;
  }
  if (x.squaredNorm() > max_radius2_) return false;
  bearing = Vec3(x.x(), x.y(), 1.0).normalized();
  return true;
}

double CameraModel::imageHalfAngle() const {
  constexpr int kStep = 4;
  double widest = 0;
  auto visit = [&](double x, double y) {
    Vec3 b;
    widest = unproject(Vec2(x, y), b) ? std::max(widest, std::acos(std::clamp(b.z(), -1.0, 1.0))) : M_PI;
  };
  for (int x = 0; x < width_; x += kStep) visit(x, 0), visit(x, height_ - 1);
  for (int y = 0; y < height_; y += kStep) visit(0, y), visit(width_ - 1, y);
  visit(width_ - 1, height_ - 1);
  return widest;
}

}  // namespace mcslam
