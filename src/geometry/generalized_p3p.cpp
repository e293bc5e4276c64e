#include "mcslam/geometry/generalized_p3p.hpp"

#include <algorithm>
#include <cmath>

#include "mcslam/geometry/generalized_p3p_roots.hpp"

namespace mcslam {

namespace {

// Triangles thinner than this (twice the area over the longest side squared) are collinear.
constexpr double kMinTriangleShape = 1e-7;
// Depths are searched up to this multiple of the longest world side; farther is numerically meaningless.
constexpr double kMaxDepthRatio = 1e4;
// A pose is kept when each point lies on its ray within this angle (radians).
constexpr double kMaxRayAngle = 1e-6;

// Univariate polynomial in l1, degree <= 8, coefficients by increasing power.
struct Poly {
  std::array<double, 9> c{};
};

Poly operator+(const Poly& a, const Poly& b) {
  Poly r;
  for (int i = 0; i < 9; ++i) r.c[i] = a.c[i] + b.c[i];
  return r;
}
Poly operator-(const Poly& a, const Poly& b) {
  Poly r;
  for (int i = 0; i < 9; ++i) r.c[i] = a.c[i] - b.c[i];
  return r;
}
int topDegree(const Poly& a) {
  int d = 8;
  while (d > 0 && a.c[d] == 0) --d;
  return d;
}
// Product truncated at degree 8; every product below stays within it by construction.
Poly operator*(const Poly& a, const Poly& b) {
  Poly r;
  const int da = topDegree(a), db = topDegree(b);
  for (int i = 0; i <= da; ++i) {
    for (int j = 0; j <= db && i + j < 9; ++j) r.c[i + j] += a.c[i] * b.c[j];
  }
  return r;
}
Poly poly(double c0, double c1 = 0, double c2 = 0) {
  Poly p;
  p.c[0] = c0;
  p.c[1] = c1;
  p.c[2] = c2;
  return p;
}

// Polynomial in (l1, l3): cell[b] is the coefficient of l3^b, itself a polynomial in l1.
struct Poly2 {
  std::array<Poly, 5> cell{};
};

// Distance constraint between rays i and j in the depths (l_i, l_j):
//   l_i^2 + l_j^2 + a l_i l_j + b l_i + c l_j + e = 0.
struct PairConstraint {
  double a, b, c, e;
  double operator()(double li, double lj) const { return li * li + lj * lj + a * li * lj + b * li + c * lj + e; }
};

PairConstraint pairConstraint(const Vec3& oi, const Vec3& di, const Vec3& oj, const Vec3& dj, double dist2) {
  const Vec3 delta = oi - oj;
  return {-2.0 * di.dot(dj), 2.0 * di.dot(delta), -2.0 * dj.dot(delta), delta.squaredNorm() - dist2};
}

// Real roots of x^2 + p x + q; a slightly negative discriminant (rounding at a double root) counts as zero.
int monicQuadraticRoots(double p, double q, double roots[2]) {
  const double half = 0.5 * p;
  double disc = half * half - q;
  if (disc < 0) {
    if (disc < -1e-9 * (half * half + std::abs(q))) return 0;
    disc = 0;
  }
  const double s = std::sqrt(disc);
  // Stable pair: the larger-magnitude root directly, the other from the product q.
  const double big = (half >= 0) ? -half - s : -half + s;
  roots[0] = big;
  roots[1] = (big != 0) ? q / big : 0.0;
  return 2;
}

// Newton on the three constraints; returns false when the Jacobian is singular or it diverges.
bool polishDepths(const PairConstraint& f12, const PairConstraint& f13, const PairConstraint& f23, Vec3& l) {
  for (int it = 0; it < 10; ++it) {
    const Vec3 F(f12(l[0], l[1]), f13(l[0], l[2]), f23(l[1], l[2]));
    Mat3 J;
    J << 2 * l[0] + f12.a * l[1] + f12.b, 2 * l[1] + f12.a * l[0] + f12.c, 0,  //
        2 * l[0] + f13.a * l[2] + f13.b, 0, 2 * l[2] + f13.a * l[0] + f13.c,   //
        0, 2 * l[1] + f23.a * l[2] + f23.b, 2 * l[2] + f23.a * l[1] + f23.c;
    const double det = J.determinant();
    if (!std::isfinite(det) || std::abs(det) < 1e-300) return F.norm() < 1e-12 * (1 + l.squaredNorm());
    const Vec3 step = J.inverse() * F;
    l -= step;
    if (!l.allFinite()) return false;
    if (step.norm() <= 1e-15 * (1 + l.norm())) break;
  }
  return true;
}

// Orthonormal frame of a triangle (columns), from its first edge and its normal.
Mat3 triangleFrame(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e1 = (b - a).normalized();
  const Vec3 e3 = (b - a).cross(c - a).normalized();
  Mat3 F;
  F.col(0) = e1;
  F.col(1) = e3.cross(e1);
  F.col(2) = e3;
  return F;
}

bool samePose(const SE3& a, const SE3& b, double scale) {
  return (a.R - b.R).norm() < 1e-9 && (a.t - b.t).norm() < 1e-9 * scale;
}

Poly2 mul(const Poly2& a, const Poly2& b) {
  Poly2 r;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; i + j < 5; ++j) r.cell[i + j] = r.cell[i + j] + a.cell[i] * b.cell[j];
  return r;
}
Poly2 sub(const Poly2& a, const Poly2& b) {
  Poly2 r;
  for (int i = 0; i < 5; ++i) r.cell[i] = a.cell[i] - b.cell[i];
  return r;
}
Poly2 add(const Poly2& a, const Poly2& b) {
  Poly2 r;
  for (int i = 0; i < 5; ++i) r.cell[i] = a.cell[i] + b.cell[i];
  return r;
}

// The octic in l1 whose real roots are the first depths of the solutions: f12 and f23 eliminate l2, then f13
// eliminates l3.
Poly octicInFirstDepth(const PairConstraint& f12, const PairConstraint& f13, const PairConstraint& f23) {
  // f12 and f23 as monic quadratics in l2: l2^2 + P l2 + Q (coefficients in l1, resp. in l3).
  const Poly p1 = poly(f12.c, f12.a), q1 = poly(f12.e, f12.b, 1.0);  // in l1
  Poly2 P1, Q1, P2, Q2;
  P1.cell[0] = p1;
  Q1.cell[0] = q1;
  P2.cell[0] = poly(f23.b);
  P2.cell[1] = poly(f23.a);
  Q2.cell[0] = poly(f23.e);
  Q2.cell[1] = poly(f23.c);
  Q2.cell[2] = poly(1.0);
  // Resultant in l2 of two monic quadratics: (Q1 - Q2)^2 + (P1 - P2) (P1 Q2 - P2 Q1).
  const Poly2 dQ = sub(Q1, Q2), dP = sub(P1, P2);
  Poly2 g = add(mul(dQ, dQ), mul(dP, sub(mul(P1, Q2), mul(P2, Q1))));

  // f13 as a monic quadratic in l3: l3^2 + p3 l3 + q3. Reduce g(l1, l3) modulo it to r1 l3 + r0.
  const Poly p3 = poly(f13.c, f13.a), q3 = poly(f13.e, f13.b, 1.0);
  for (int k = 4; k >= 2; --k) {
    g.cell[k - 1] = g.cell[k - 1] - g.cell[k] * p3;
    g.cell[k - 2] = g.cell[k - 2] - g.cell[k] * q3;
    g.cell[k] = Poly{};
  }
  const Poly& r1 = g.cell[1];
  const Poly& r0 = g.cell[0];
  // Resultant in l3 of (r1 l3 + r0) and f13: r0^2 - p3 r0 r1 + q3 r1^2, the octic in l1.
  return r0 * r0 - p3 * r0 * r1 + q3 * r1 * r1;
}

// The poses of one root l1 of the octic: candidate depths l2 from f12 and l3 from f13 (two each); each pair that
// satisfies f23 (polished) gives the pose of the two congruent triangles, kept when every point lies on its ray.
void addPosesOfRoot(double l1, const PairConstraint& f12, const PairConstraint& f13, const PairConstraint& f23,
                    const std::array<BodyRay, 3>& rays, const std::array<Vec3, 3>& points_w,
                    const std::array<Vec3, 3>& o, const std::array<Vec3, 3>& d, double scale, Cheirality cheirality,
                    GeneralizedP3PSolutions& solutions) {
  const Vec3& X1 = points_w[0];
  const Vec3& X2 = points_w[1];
  const Vec3& X3 = points_w[2];
  double l2s[2], l3s[2];
  const int n2 = monicQuadraticRoots(f12.a * l1 + f12.c, l1 * l1 + f12.b * l1 + f12.e, l2s);
  const int n3 = monicQuadraticRoots(f13.a * l1 + f13.c, l1 * l1 + f13.b * l1 + f13.e, l3s);
  for (int i2 = 0; i2 < n2; ++i2) {
    for (int i3 = 0; i3 < n3; ++i3) {
      Vec3 l(l1, l2s[i2], l3s[i3]);
      const double size = 1.0 + l.squaredNorm();
      if (std::abs(f23(l[1], l[2])) > 1e-4 * size) continue;
      if (!polishDepths(f12, f13, f23, l)) continue;
      if (cheirality == Cheirality::InFront && !(l.minCoeff() > 0)) continue;

      // Pose from the two congruent triangles: body points (scaled back) -> world points.
      const Vec3 B1 = (o[0] + l[0] * d[0]) * scale, B2 = (o[1] + l[1] * d[1]) * scale,
                 B3 = (o[2] + l[2] * d[2]) * scale;
      const Mat3 R_w_b = triangleFrame(X1, X2, X3) * triangleFrame(B1, B2, B3).transpose();
      const Vec3 t_w_b = (X1 + X2 + X3) / 3.0 - R_w_b * (B1 + B2 + B3) / 3.0;
      const SE3 T_w_b(R_w_b, t_w_b);
      if (!R_w_b.allFinite() || !t_w_b.allFinite()) continue;

      // Verify against the input: each point on its ray (and in front when asked).
      bool ok = true;
      for (int i = 0; i < 3 && ok; ++i) {
        const Vec3 v = R_w_b.transpose() * (points_w[i] - t_w_b) - rays[i].origin;
        const double along = v.dot(d[i]);
        ok = v.cross(d[i]).norm() <= kMaxRayAngle * std::max(v.norm(), 1e-12 * scale) &&
             (cheirality == Cheirality::Any || along > 0);
      }
      if (!ok) continue;
      bool duplicate = false;
      for (int s = 0; s < solutions.count && !duplicate; ++s) duplicate = samePose(solutions.T_w_b[s], T_w_b, scale);
      if (!duplicate && solutions.count < GeneralizedP3PSolutions::kMaxSolutions) {
        solutions.T_w_b[solutions.count++] = T_w_b;
      }
    }
  }
}

}  // namespace

int solveGeneralizedP3P(const std::array<BodyRay, 3>& rays, const std::array<Vec3, 3>& points_w,
                        GeneralizedP3PSolutions& solutions, Cheirality cheirality) {
  solutions.count = 0;
  const Vec3& X1 = points_w[0];
  const Vec3& X2 = points_w[1];
  const Vec3& X3 = points_w[2];
  const double d12 = (X1 - X2).squaredNorm(), d13 = (X1 - X3).squaredNorm(), d23 = (X2 - X3).squaredNorm();
  const double longest2 = std::max({d12, d13, d23});
  if (!(longest2 > 0) || !std::isfinite(longest2)) return 0;
  if ((X2 - X1).cross(X3 - X1).norm() < kMinTriangleShape * longest2) return 0;

  // Work in units of the longest side so that the polynomial's coefficients are of order one.
  const double scale = std::sqrt(longest2);
  const double inv = 1.0 / scale;
  std::array<Vec3, 3> o, d;
  for (int i = 0; i < 3; ++i) {
    const double n = rays[i].direction.norm();
    if (!(n > 0) || !std::isfinite(n)) return 0;
    d[i] = rays[i].direction / n;
    o[i] = rays[i].origin * inv;
  }
  const double inv2 = inv * inv;
  const PairConstraint f12 = pairConstraint(o[0], d[0], o[1], d[1], d12 * inv2);
  const PairConstraint f13 = pairConstraint(o[0], d[0], o[2], d[2], d13 * inv2);
  const PairConstraint f23 = pairConstraint(o[1], d[1], o[2], d[2], d23 * inv2);

  const Poly octic = octicInFirstDepth(f12, f13, f23);

  double roots[kMaxPolynomialDegree];
  const double lo = (cheirality == Cheirality::InFront) ? 0.0 : -kMaxDepthRatio;
  const int num_roots = realPolynomialRoots(octic.c.data(), 8, lo, kMaxDepthRatio, roots);

  for (int r = 0; r < num_roots && solutions.count < GeneralizedP3PSolutions::kMaxSolutions; ++r) {
    addPosesOfRoot(roots[r], f12, f13, f23, rays, points_w, o, d, scale, cheirality, solutions);
  }
  return solutions.count;
}

}  // namespace mcslam
