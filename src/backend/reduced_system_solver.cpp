#include "reduced_system_solver.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace mcslam::backend {

namespace {
// CHOLMOD's peak for an n x n matrix with a dense factor: the factor (values and indices), the
// matrix and its permuted copy, AMD's workspace and the solve's dense vectors, all O(n^2) bytes
// with small constants; the fixed part covers Common's workspace.
size_t arenaBytes(int n) { return (size_t(256) << 10) + size_t(96) * n * n; }
}  // namespace

ReducedSystemSolver::ReducedSystemSolver(int max_blocks)
    : max_blocks_(max_blocks), ld_(kBlock * max_blocks), arena_(arenaBytes(kBlock * max_blocks)) {
  pattern_.assign(size_t(max_blocks) * max_blocks, 0);
  const size_t max_nnz = size_t(ld_) * (ld_ + 1) / 2;
  gather_.resize(max_nnz);
  ArenaScope scope(arena_);
  cholmod_start(&common_);
  common_.print = 0;
  // Simplicial: the reduced system is small (tens of blocks), where the supernodal path's BLAS
  // calls buy nothing; AMD only, so METIS (which allocates on its own) is never tried.
  common_.supernodal = CHOLMOD_SIMPLICIAL;
  common_.final_ll = 1;
  common_.nmethods = 1;
  common_.method[0].ordering = CHOLMOD_AMD;
  A_ = cholmod_allocate_sparse(ld_, ld_, max_nnz, /*sorted=*/1, /*packed=*/1, /*stype=*/1, CHOLMOD_REAL, &common_);
  B_ = cholmod_allocate_dense(ld_, 1, ld_, CHOLMOD_REAL, &common_);
  if (!A_ || !B_) throw std::runtime_error("ReducedSystemSolver: CHOLMOD allocation failed");
}

ReducedSystemSolver::~ReducedSystemSolver() {
  ArenaScope scope(arena_);
  cholmod_free_factor(&L_, &common_);
  cholmod_free_sparse(&A_, &common_);
  cholmod_free_dense(&B_, &common_);
  cholmod_free_dense(&X_, &common_);
  cholmod_free_dense(&Y_, &common_);
  cholmod_free_dense(&E_, &common_);
  cholmod_finish(&common_);
}

bool ReducedSystemSolver::setStructure(int num_blocks, const uint8_t* pattern) {
  const size_t used = size_t(max_blocks_) * num_blocks;
  if (num_blocks == num_blocks_ && std::equal(pattern, pattern + used, pattern_.begin())) return false;
  std::copy(pattern, pattern + used, pattern_.begin());
  num_blocks_ = num_blocks;

  // Upper triangle in compressed columns, rows sorted: for column j of block b, the rows of
  // every block a <= b in the pattern (for a == b only up to the diagonal).
  const int n = kBlock * num_blocks;
  auto* Ap = static_cast<int*>(A_->p);
  auto* Ai = static_cast<int*>(A_->i);
  int k = 0;
  for (int b = 0; b < num_blocks; ++b) {
    for (int c = 0; c < kBlock; ++c) {
      const int j = kBlock * b + c;
      Ap[j] = k;
      for (int a = 0; a <= b; ++a) {
        if (!pattern[a * max_blocks_ + b]) continue;
        const int rows = a == b ? c + 1 : kBlock;
        for (int r = 0; r < rows; ++r) {
          Ai[k] = kBlock * a + r;
          gather_[k] = Ai[k] + j * ld_;
          ++k;
        }
      }
    }
  }
  Ap[n] = k;
  A_->nrow = A_->ncol = n;

  ArenaScope scope(arena_);
  cholmod_free_factor(&L_, &common_);
  L_ = cholmod_analyze(A_, &common_);
  ++analyses_;
  return true;
}

bool ReducedSystemSolver::solve(const double* S, const double* rhs, double* x) {
  if (!L_ || num_blocks_ <= 0) return false;
  const int n = kBlock * num_blocks_;
  auto* Ax = static_cast<double*>(A_->x);
  const int nnz = static_cast<int*>(A_->p)[n];
  for (int k = 0; k < nnz; ++k) Ax[k] = S[gather_[k]];

  ArenaScope scope(arena_);
  cholmod_factorize(A_, L_, &common_);
  if (common_.status != CHOLMOD_OK || L_->minor < L_->n) return false;
  B_->nrow = n;
  B_->d = n;
  std::memcpy(B_->x, rhs, sizeof(double) * n);
  if (!cholmod_solve2(CHOLMOD_A, L_, B_, nullptr, &X_, nullptr, &Y_, &E_, &common_)) return false;
  std::memcpy(x, X_->x, sizeof(double) * n);
  return true;
}

}  // namespace mcslam::backend
