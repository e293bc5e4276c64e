#pragma once
// Eigen-decomposition of a small symmetric matrix by cyclic Jacobi rotations, in place on
// caller-owned storage. Eigen's SelfAdjointEigenSolver allocates temporaries on every compute()
// for dynamic sizes; this does not, and Jacobi is as accurate as it gets for the tens of
// dimensions of the extrinsic prior.
#include <Eigen/Core>
#include <cmath>

namespace mcslam::backend {

// On return A is diagonal (the eigenvalues, unsorted) and V holds the eigenvectors in columns:
// A_in = V diag(A) V^T. V must have A's size.
inline void jacobiEigen(Eigen::MatrixXd& A, Eigen::MatrixXd& V) {
  const int n = static_cast<int>(A.rows());
  V.setIdentity();
  for (int sweep = 0; sweep < 60; ++sweep) {
    double off = 0, diag = 0;
    for (int q = 0; q < n; ++q) {
      diag += A(q, q) * A(q, q);
      for (int p = 0; p < q; ++p) off += A(p, q) * A(p, q);
    }
    if (off <= 1e-32 * diag || off == 0) return;
    for (int q = 1; q < n; ++q) {
      for (int p = 0; p < q; ++p) {
        const double apq = A(p, q);
        if (apq == 0) continue;
        // Rotation that zeroes A(p, q): t = tan(angle), the smaller root for stability.
        const double theta = (A(q, q) - A(p, p)) / (2 * apq);
        const double t = (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < n; ++k) {
          const double akp = A(k, p), akq = A(k, q);
          A(k, p) = c * akp - s * akq;
          A(k, q) = s * akp + c * akq;
        }
        for (int k = 0; k < n; ++k) {
          const double apk = A(p, k), aqk = A(q, k);
          A(p, k) = c * apk - s * aqk;
          A(q, k) = s * apk + c * aqk;
        }
        for (int k = 0; k < n; ++k) {
          const double vkp = V(k, p), vkq = V(k, q);
          V(k, p) = c * vkp - s * vkq;
          V(k, q) = s * vkp + c * vkq;
        }
      }
    }
  }
}

}  // namespace mcslam::backend
