#include "mcslam/geometry/relative_pose_solvers.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <cstdint>

namespace mcslam::relative_pose_detail {

namespace {

using Mat9 = Eigen::Matrix<double, 9, 9>;
using Vec9 = Eigen::Matrix<double, 9, 1>;
using Mat10 = Eigen::Matrix<double, 10, 10>;

// Polynomials of degree <= 3 in (x, y, z), by coefficient of each monomial. The ten monomials of degree 3 come
// first: the five-point solver eliminates them, and the ten after them are the basis of its quotient ring.
struct Exponents {
  int x, y, z;
};
constexpr int kMonomials = 20;
constexpr std::array<Exponents, kMonomials> kExponents = {
    {{3, 0, 0}, {2, 1, 0}, {2, 0, 1}, {1, 2, 0}, {1, 1, 1}, {1, 0, 2}, {0, 3, 0}, {0, 2, 1}, {0, 1, 2}, {0, 0, 3},
     {2, 0, 0}, {1, 1, 0}, {1, 0, 1}, {0, 2, 0}, {0, 1, 1}, {0, 0, 2}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 0, 0}}};
constexpr int kDegree3 = 10;  // monomials [0, 10) are of degree 3, [10, 20) the quotient basis
constexpr int kBasisX = 16, kBasisY = 17, kBasisZ = 18, kBasisOne = 19;

constexpr int monomialIndex(int x, int y, int z) {
  for (int i = 0; i < kMonomials; ++i)
    if (kExponents[i].x == x && kExponents[i].y == y && kExponents[i].z == z) return i;
  return -1;
}

// The monomial of each product of two monomials, -1 above degree 3 (the products formed here never get there:
// linear entries, at most three factors).
constexpr auto kProducts = [] {
  std::array<std::array<int, kMonomials>, kMonomials> table{};
  for (int i = 0; i < kMonomials; ++i)
    for (int j = 0; j < kMonomials; ++j)
      table[i][j] = monomialIndex(kExponents[i].x + kExponents[j].x, kExponents[i].y + kExponents[j].y,
                                  kExponents[i].z + kExponents[j].z);
  return table;
}();

using Poly = std::array<double, kMonomials>;

Poly operator*(const Poly& p, const Poly& q) {
  Poly r{};
  for (int i = 0; i < kMonomials; ++i) {
    if (p[i] == 0) continue;
    for (int j = 0; j < kMonomials; ++j) {
      if (q[j] == 0 || kProducts[i][j] < 0) continue;
      r[kProducts[i][j]] += p[i] * q[j];
    }
  }
  return r;
}

Poly operator+(Poly p, const Poly& q) {
  for (int i = 0; i < kMonomials; ++i) p[i] += q[i];
  return p;
}

Poly operator-(Poly p, const Poly& q) {
  for (int i = 0; i < kMonomials; ++i) p[i] -= q[i];
  return p;
}

Poly operator*(double s, Poly p) {
  for (double& c : p) c *= s;
  return p;
}

using PolyMat3 = std::array<std::array<Poly, 3>, 3>;

// The ten cubic constraints on E = x X + y Y + z Z + W: det(E) = 0 and 2 E E' E - trace(E E') E = 0.
Eigen::Matrix<double, 10, kMonomials> cubicConstraints(const PolyMat3& E) {
  Eigen::Matrix<double, 10, kMonomials> M;
  const Poly det = E[0][0] * (E[1][1] * E[2][2] - E[1][2] * E[2][1]) -
                   E[0][1] * (E[1][0] * E[2][2] - E[1][2] * E[2][0]) +
                   E[0][2] * (E[1][0] * E[2][1] - E[1][1] * E[2][0]);
  for (int m = 0; m < kMonomials; ++m) M(0, m) = det[m];
  PolyMat3 EEt{};
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) EEt[j][k] = EEt[j][k] + E[j][l] * E[k][l];
  const Poly trace = EEt[0][0] + EEt[1][1] + EEt[2][2];
  for (int j = 0; j < 3; ++j) {
    for (int k = 0; k < 3; ++k) {
      Poly c{};
      for (int l = 0; l < 3; ++l) c = c + EEt[j][l] * E[l][k];
      c = 2.0 * c - trace * E[j][k];
      for (int m = 0; m < kMonomials; ++m) M(1 + 3 * j + k, m) = c[m];
    }
  }
  return M;
}

Mat3 rowMajor3(const Vec9& v) {
  Mat3 M;
  M << v(0), v(1), v(2), v(3), v(4), v(5), v(6), v(7), v(8);
  return M;
}

Vec9 rowMajorVector(const Mat3& M) {
  Vec9 v;
  v << M(0, 0), M(0, 1), M(0, 2), M(1, 0), M(1, 1), M(1, 2), M(2, 0), M(2, 1), M(2, 2);
  return v;
}

}  // namespace

int essentialsInSpan(const std::array<Mat3, 4>& basis, std::array<Mat3, 10>& E) {
  PolyMat3 P{};
  for (int j = 0; j < 3; ++j) {
    for (int k = 0; k < 3; ++k) {
      P[j][k][kBasisX] = basis[0](j, k);
      P[j][k][kBasisY] = basis[1](j, k);
      P[j][k][kBasisZ] = basis[2](j, k);
      P[j][k][kBasisOne] = basis[3](j, k);
    }
  }
  const Eigen::Matrix<double, 10, kMonomials> M = cubicConstraints(P);
  // Each cubic monomial as a combination of the basis: cubic = -G basis.
  const Eigen::PartialPivLU<Mat10> lu(M.leftCols<kDegree3>());
  const Mat10 G = lu.solve(M.rightCols<kMonomials - kDegree3>());
  if (!G.allFinite()) return 0;
  // Multiplication by x in the basis: x b is a basis monomial or a cubic one.
  Mat10 action = Mat10::Zero();
  for (int i = 0; i < 10; ++i) {
    const Exponents& b = kExponents[kDegree3 + i];
    const int product = monomialIndex(b.x + 1, b.y, b.z);
    if (product < kDegree3) {
      action.row(i) = -G.row(product);
    } else {
      action(i, product - kDegree3) = 1;
    }
  }
  // At each solution the basis monomials' values are an eigenvector, its eigenvalue x.
  const Eigen::EigenSolver<Mat10> eigen(action, true);
  int count = 0;
  for (int i = 0; i < 10; ++i) {
    if (std::abs(eigen.eigenvalues()(i).imag()) > 1e-9 * std::max(1.0, std::abs(eigen.eigenvalues()(i).real())))
      continue;
    const Eigen::Matrix<double, 10, 1> u = eigen.eigenvectors().col(i).real();
    const double one = u(kBasisOne - kDegree3);
    if (!(std::abs(one) > 1e-12 * u.norm())) continue;  // a solution at infinity of the chart W = 1
    const double x = u(kBasisX - kDegree3) / one, y = u(kBasisY - kDegree3) / one, z = u(kBasisZ - kDegree3) / one;
    const Mat3 e = x * basis[0] + y * basis[1] + z * basis[2] + basis[3];
    const double norm = e.norm();
    if (!(norm > 0) || !e.allFinite()) continue;
    E[count++] = e / norm;
  }
  return count;
}

int fivePointEssential(const std::array<Vec3, 5>& d1, const std::array<Vec3, 5>& d2, std::array<Mat3, 10>& E) {
  // Each match is one row of d1' E d2 = 0 in E's nine entries (row-major); four null vectors span E.
  Mat9 Q = Mat9::Zero();
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) Q(i, 3 * j + k) = d1[i](j) * d2[i](k);
  const Eigen::JacobiSVD<Mat9> svd(Q, Eigen::ComputeFullV);
  const Mat9& V = svd.matrixV();
  return essentialsInSpan({rowMajor3(V.col(5)), rowMajor3(V.col(6)), rowMajor3(V.col(7)), rowMajor3(V.col(8))}, E);
}

void decomposeEssential(const Mat3& E, Mat3& R_a, Mat3& R_b, Vec3& t) {
  const Eigen::JacobiSVD<Mat3> svd(E, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 U = svd.matrixU(), V = svd.matrixV();
  if (U.determinant() < 0) U = -U;  // E is defined up to sign
  if (V.determinant() < 0) V = -V;
  Mat3 W;
  W << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  R_a = U * W * V.transpose();
  R_b = U * W.transpose() * V.transpose();
  t = U.col(2);
}

bool linearGeneralizedPose(std::span<const RayPair> rays, std::span<const uint8_t> mask, std::array<SE3, 2>& poses) {
  // Row of a match: [d1 (x) d2, d1 (x) m2 + m1 (x) d2] . [vec E; vec R] = 0, with the lines' moments m = c x d.
  Eigen::Matrix<double, 18, 18> G = Eigen::Matrix<double, 18, 18>::Zero();
  int used = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    if (!mask[i]) continue;
    const RayPair& r = rays[i];
    const Vec3 m1 = r.c1.cross(r.d1), m2 = r.c2.cross(r.d2);
    Eigen::Matrix<double, 18, 1> a;
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 3; ++k) {
        a(3 * j + k) = r.d1(j) * r.d2(k);
        a(9 + 3 * j + k) = r.d1(j) * m2(k) + m1(j) * r.d2(k);
      }
    }
    G.noalias() += a * a.transpose();
    ++used;
  }
  if (used < 17) return false;
  // Minimizing over R for each E leaves the Schur complement in E; the pseudo-inverse drops the direction
  // R = I that matches within one camera leave free.
  const Mat9 Gee = G.topLeftCorner<9, 9>(), Ger = G.topRightCorner<9, 9>(), Grr = G.bottomRightCorner<9, 9>();
  const Eigen::SelfAdjointEigenSolver<Mat9> rr(Grr);
  const double largest = rr.eigenvalues().maxCoeff();
  if (!(largest > 0)) return false;
  Vec9 inverse;
  for (int k = 0; k < 9; ++k) inverse(k) = rr.eigenvalues()(k) > 1e-10 * largest ? 1.0 / rr.eigenvalues()(k) : 0.0;
  const Mat9 B = Ger * rr.eigenvectors();
  const Mat9 S = Gee - B * inverse.asDiagonal() * B.transpose();
  // E is in the null space of S. That space has more than one dimension for some rigs (axial ones: a stereo pair
  // with matches across its cameras): of the essential matrices in the span of S's four smallest eigenvectors,
  // the one S weighs least. The smallest eigenvector is the span's constant term: where the null space has one
  // dimension, E is that vector itself.
  const Eigen::SelfAdjointEigenSolver<Mat9> es(S);
  const Mat9& V = es.eigenvectors();
  std::array<Mat3, 10> essentials;
  const int found = essentialsInSpan(
      {rowMajor3(V.col(1)), rowMajor3(V.col(2)), rowMajor3(V.col(3)), rowMajor3(V.col(0))}, essentials);
  Mat3 E = rowMajor3(V.col(0));
  double least = INFINITY;
  for (int k = 0; k < found; ++k) {
    const Vec9 e = rowMajorVector(essentials[k]);
    const double weight = e.dot(S * e);
    if (weight < least) {
      least = weight;
      E = essentials[k];
    }
  }
  if (!E.allFinite()) return false;
  Mat3 R_candidates[2];
  Vec3 direction;
  decomposeEssential(E, R_candidates[0], R_candidates[1], direction);
  // For a rotation, the constraint is affine in the length s along the direction: s alpha + beta = 0.
  for (int c = 0; c < 2; ++c) {
    const Mat3& R = R_candidates[c];
    double alpha_alpha = 0, alpha_beta = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      if (!mask[i]) continue;
      const RayPair& r = rays[i];
      const Vec3 Rd2 = R * r.d2;
      const double alpha = r.d1.dot(direction.cross(Rd2));
      const double beta = r.d1.dot(R * r.c2.cross(r.d2)) + r.c1.cross(r.d1).dot(Rd2);
      alpha_alpha += alpha * alpha;
      alpha_beta += alpha * beta;
    }
    const double s = alpha_alpha > 0 ? -alpha_beta / alpha_alpha : 0.0;
    poses[c] = SE3(R, s * direction);
  }
  return true;
}

}  // namespace mcslam::relative_pose_detail
