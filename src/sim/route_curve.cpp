#include "route_curve.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "mcslam/core/error.hpp"

namespace mcslam::sim {

namespace {

double wrapAngle(double a) {
  while (a > M_PI) a -= 2 * M_PI;
  while (a < -M_PI) a += 2 * M_PI;
  return a;
}

// Per corner: turn angle, radius and tangent length of its fillet. Throws InputError when two fillets do not
// fit on the segment between their corners.
struct Fillets {
  std::vector<double> turn, tangent, radius;
};

Fillets cornerFillets(const RouteSpec& spec) {
  const auto& P = spec.corners;
  const int n = static_cast<int>(P.size());
  Fillets f{std::vector<double>(n), std::vector<double>(n), std::vector<double>(n)};
  for (int i = 0; i < n; ++i) {
    const Vec2 a = (P[i] - P[(i + n - 1) % n]).normalized(), b = (P[(i + 1) % n] - P[i]).normalized();
    f.turn[i] = std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));
    f.radius[i] = i < static_cast<int>(spec.radii.size()) ? spec.radii[i] : 1.0;
    f.tangent[i] = f.radius[i] * std::tan(std::abs(f.turn[i]) / 2);
  }
  for (int i = 0; i < n; ++i) {  // fillets must fit on their segments
    const double seg = (P[(i + 1) % n] - P[i]).norm();
    if (f.tangent[i] + f.tangent[(i + 1) % n] > seg + 1e-9) {
      throw InputError("route: corner radii too large for the segment from corner " + std::to_string(i) + " to " +
                       std::to_string((i + 1) % n));
    }
  }
  return f;
}

struct Piece {
  double length, curvature;
};

// Piecewise-constant curvature, starting half-way along the segment from corner 0 to corner 1 (first_half
// from there to the first fillet); `stops` gets the arc length where each stop corner's arc starts.
std::vector<Piece> curvaturePieces(const RouteSpec& spec, const Fillets& f, double first_half,
                                   std::vector<double>& stops) {
  const auto& P = spec.corners;
  const int n = static_cast<int>(P.size());
  std::vector<Piece> pieces;
  double s = 0;
  pieces.push_back({first_half, 0.0});
  s += first_half;
  for (int k = 1; k <= n; ++k) {
    const int i = k % n;
    if (std::find(spec.stops.begin(), spec.stops.end(), i) != spec.stops.end()) stops.push_back(s);
    const double arc = f.radius[i] * std::abs(f.turn[i]);
    pieces.push_back({arc, f.turn[i] / arc});
    s += arc;
    const double seg = (P[(i + 1) % n] - P[i]).norm() - f.tangent[i] - f.tangent[(i + 1) % n];
    const double straight = k == n ? first_half : seg;
    pieces.push_back({straight, 0.0});
    s += straight;
  }
  return pieces;
}

// The pieces' curvature at the centres of m steps, then smoothed by a periodic box of 2 half + 1 steps (which
// keeps the total turn, so the heading still closes).
std::vector<double> smoothCurvature(const std::vector<Piece>& pieces, int m, double step, int half) {
  std::vector<double> kappa(m, 0.0);
  {
    std::size_t pi = 0;
    double start = 0;
    for (int j = 0; j < m; ++j) {
      const double sj = (j + 0.5) * step;
      while (pi + 1 < pieces.size() && sj > start + pieces[pi].length) start += pieces[pi++].length;
      kappa[j] = pieces[pi].curvature;
    }
  }
  std::vector<double> curvature(m, 0.0);
  double acc = 0;
  for (int j = -half; j <= half; ++j) acc += kappa[(j % m + m) % m];
  for (int j = 0; j < m; ++j) {
    curvature[j] = acc / (2 * half + 1);
    acc += kappa[(j + half + 1) % m] - kappa[((j - half) % m + m) % m];
  }
  return curvature;
}

}  // namespace

RouteCurve::RouteCurve(const RouteSpec& spec, double smoothing, double step) : step_(step) {
  const auto& P = spec.corners;
  const int n = static_cast<int>(P.size());
  if (n < 3) throw InputError("route: needs at least 3 corners, has " + std::to_string(n));
  const Fillets f = cornerFillets(spec);
  const double first_half = 0.5 * ((P[1] - P[0]).norm() - f.tangent[0] - f.tangent[1]);
  const std::vector<Piece> pieces = curvaturePieces(spec, f, first_half, stops_);
  double s = 0;
  for (const Piece& piece : pieces) s += piece.length;
  length_ = s;
  const int m = static_cast<int>(std::ceil(length_ / step_));
  step_ = length_ / m;
  const int half = std::max(1, static_cast<int>(std::lround(0.5 * smoothing / step_)));
  curvature_ = smoothCurvature(pieces, m, step_, half);
  // Integrate heading and position; spread the small position closure error linearly.
  const Vec2 start_dir = (P[1] - P[0]).normalized();
  const Vec2 start_point = P[0] + (f.tangent[0] + first_half) * start_dir;
  double heading = std::atan2(start_dir.y(), start_dir.x());
  points_.resize(m + 1);
  heading_.resize(m + 1);
  points_[0] = start_point;
  heading_[0] = heading;
  for (int j = 0; j < m; ++j) {
    const double mid = heading + 0.5 * curvature_[j] * step_;
    points_[j + 1] = points_[j] + step_ * Vec2(std::cos(mid), std::sin(mid));
    heading += curvature_[j] * step_;
    heading_[j + 1] = heading;
  }
  const Vec2 gap = points_[m] - points_[0];
  for (int j = 0; j <= m; ++j) points_[j] -= gap * (static_cast<double>(j) / m);
  curvature_.push_back(curvature_[0]);
}

void RouteCurve::at(double s, Vec2& p, double& heading, double& curvature) const {
  s = std::fmod(s, length_);
  if (s < 0) s += length_;
  const double x = s / step_;
  const int j = std::min(static_cast<int>(x), static_cast<int>(points_.size()) - 2);
  const double f = x - j;
  p = (1 - f) * points_[j] + f * points_[j + 1];
  heading = heading_[j] + f * wrapAngle(heading_[j + 1] - heading_[j]);
  curvature = (1 - f) * curvature_[j] + f * curvature_[j + 1];
}

double RouteCurve::distanceTo(const Vec2& q) const {
  double best = 1e30;
  for (std::size_t j = 0; j + 1 < points_.size(); ++j) {
    const Vec2 a = points_[j], ab = points_[j + 1] - a;
    const double f = std::clamp((q - a).dot(ab) / std::max(ab.squaredNorm(), 1e-12), 0.0, 1.0);
    best = std::min(best, (a + f * ab - q).norm());
  }
  return best;
}

void checkRouteClearance(const World& world, const RouteCurve& curve, double clearance) {
  const auto& pts = curve.points();
  const int stride = std::max(1, static_cast<int>(0.05 / (curve.length() / (pts.size() - 1))));
  for (std::size_t j = 0; j < pts.size(); j += stride) {
    for (double z : {0.15, 0.6, 1.0, 1.5}) {
      const Vec3 o(pts[j].x(), pts[j].y(), z);
      for (int a = 0; a < 16; ++a) {
        const double ang = 2 * M_PI * a / 16;
        const Vec3 dir(std::cos(ang), std::sin(ang), 0);
        if (auto hit = world.intersect(o, dir, clearance, 0.0, false)) {
          char buf[200];
          std::snprintf(buf, sizeof(buf), "route passes %.2f m from geometry at (%.2f, %.2f, %.2f) (needs %.2f m)",
                        hit->t, o.x(), o.y(), z, clearance);
          throw InputError(world.name() + ": " + buf);
        }
      }
    }
  }
}

}  // namespace mcslam::sim
