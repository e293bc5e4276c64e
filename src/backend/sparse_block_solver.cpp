#include "sparse_block_solver.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace mcslam::backend {

namespace {

// Nonzeros of the upper triangle: N (N + 1) / 2 per diagonal block, N^2 per off-diagonal one.
std::size_t upperNonzeros(int n, int blocks, int pairs) {
  const auto block = static_cast<std::size_t>(n);
  return block * (block + 1) / 2 * static_cast<std::size_t>(blocks) + block * block * static_cast<std::size_t>(pairs);
}

// CHOLMOD's peak for a pose graph: the factor (AMD keeps a chain with loops at a few times the matrix's nonzeros),
// the matrix's permuted copy, AMD's workspace, the solve's vectors; the fixed part covers Common's workspace.
std::size_t arenaBytes(int n, int blocks, int pairs) {
  return (std::size_t{1} << 20) + 160 * upperNonzeros(n, blocks, pairs) +
         std::size_t{1024} * static_cast<std::size_t>(blocks);
}

}  // namespace

template <int N>
SparseBlockSolver<N>::SparseBlockSolver(int max_blocks, int max_pairs)
    : max_blocks_(max_blocks),
      max_pairs_(max_pairs),
      arena_(arenaBytes(N, max_blocks, max_pairs)),
      diagonal_(static_cast<std::size_t>(max_blocks)),
      off_(static_cast<std::size_t>(max_pairs)),
      keys_(static_cast<std::size_t>(max_pairs)),
      previous_keys_(static_cast<std::size_t>(max_pairs)),
      order_(static_cast<std::size_t>(max_pairs)),
      entry_low_(static_cast<std::size_t>(max_pairs)),
      first_entry_of_column_(static_cast<std::size_t>(max_blocks) + 1) {
  const int n = kBlock * max_blocks;
  ArenaScope scope(arena_);
  cholmod_start(&common_);
  common_.print = 0;
  // Simplicial LL' with AMD only: no BLAS, and METIS (which allocates on its own) is never tried.
  common_.supernodal = CHOLMOD_SIMPLICIAL;
  common_.final_ll = 1;
  common_.nmethods = 1;
  common_.method[0].ordering = CHOLMOD_AMD;
  A_ = cholmod_allocate_sparse(n, n, upperNonzeros(N, max_blocks, max_pairs), /*sorted=*/1, /*packed=*/1, /*stype=*/1,
                               CHOLMOD_REAL, &common_);
  B_ = cholmod_allocate_dense(n, 1, n, CHOLMOD_REAL, &common_);
  if (!A_ || !B_) throw std::runtime_error("SparseBlockSolver: CHOLMOD allocation failed");
}

template <int N>
SparseBlockSolver<N>::~SparseBlockSolver() {
  ArenaScope scope(arena_);
  cholmod_free_factor(&L_, &common_);
  cholmod_free_sparse(&A_, &common_);
  cholmod_free_dense(&B_, &common_);
  cholmod_free_dense(&X_, &common_);
  cholmod_free_dense(&Y_, &common_);
  cholmod_free_dense(&E_, &common_);
  cholmod_finish(&common_);
}

template <int N>
bool SparseBlockSolver<N>::setStructure(int num_blocks, std::span<const BlockPair> pairs,
                                        std::span<int32_t> entry_of_pair) {
  if (num_blocks > max_blocks_ || static_cast<int>(pairs.size()) > max_pairs_)
    throw std::logic_error("SparseBlockSolver: structure beyond the capacity");
  const auto key = [this](const BlockPair& p) {
    return static_cast<int64_t>(std::min(p.a, p.b)) + static_cast<int64_t>(std::max(p.a, p.b)) * max_blocks_;
  };
  const int n_pairs = static_cast<int>(pairs.size());
  for (int k = 0; k < n_pairs; ++k) order_[static_cast<std::size_t>(k)] = k;
  std::sort(order_.begin(), order_.begin() + n_pairs, [&](int32_t x, int32_t y) {
    return key(pairs[static_cast<std::size_t>(x)]) < key(pairs[static_cast<std::size_t>(y)]);
  });
  entries_ = 0;
  for (int k = 0; k < n_pairs; ++k) {
    const BlockPair& p = pairs[static_cast<std::size_t>(order_[static_cast<std::size_t>(k)])];
    const int64_t kk = key(p);
    if (entries_ == 0 || keys_[static_cast<std::size_t>(entries_ - 1)] != kk) {
      keys_[static_cast<std::size_t>(entries_)] = kk;
      entry_low_[static_cast<std::size_t>(entries_)] = std::min(p.a, p.b);
      ++entries_;
    }
    entry_of_pair[static_cast<std::size_t>(order_[static_cast<std::size_t>(k)])] = entries_ - 1;
  }
  const bool same = num_blocks == num_blocks_ && entries_ == previous_entries_ &&
                    std::equal(keys_.begin(), keys_.begin() + entries_, previous_keys_.begin());
  if (same) return false;
  std::copy(keys_.begin(), keys_.begin() + entries_, previous_keys_.begin());
  previous_entries_ = entries_;
  num_blocks_ = num_blocks;
  buildPattern();
  ArenaScope scope(arena_);
  cholmod_free_factor(&L_, &common_);
  L_ = cholmod_analyze(A_, &common_);
  ++analyses_;
  return true;
}

template <int N>
void SparseBlockSolver<N>::buildPattern() {
  // Entries are sorted by their high variable (the block column), then the low one (the block row).
  int e = 0;
  for (int b = 0; b <= num_blocks_; ++b) {
    while (e < entries_ && keys_[static_cast<std::size_t>(e)] / max_blocks_ < b) ++e;
    first_entry_of_column_[static_cast<std::size_t>(b)] = e;
  }
  auto* Ap = static_cast<int*>(A_->p);
  auto* Ai = static_cast<int*>(A_->i);
  int k = 0;
  for (int b = 0; b < num_blocks_; ++b) {
    const int first = first_entry_of_column_[static_cast<std::size_t>(b)];
    const int last = first_entry_of_column_[static_cast<std::size_t>(b) + 1];
    for (int c = 0; c < kBlock; ++c) {
      Ap[kBlock * b + c] = k;
      for (int entry = first; entry < last; ++entry)
        for (int r = 0; r < kBlock; ++r) Ai[k++] = kBlock * entry_low_[static_cast<std::size_t>(entry)] + r;
      for (int r = 0; r <= c; ++r) Ai[k++] = kBlock * b + r;
    }
  }
  Ap[kBlock * num_blocks_] = k;
  A_->nrow = A_->ncol = static_cast<std::size_t>(kBlock * num_blocks_);
}

template <int N>
void SparseBlockSolver<N>::setZero() {
  for (int v = 0; v < num_blocks_; ++v) diagonal_[static_cast<std::size_t>(v)].setZero();
  for (int e = 0; e < entries_; ++e) off_[static_cast<std::size_t>(e)].setZero();
}

template <int N>
bool SparseBlockSolver<N>::solve(const double* rhs, double* x) {
  if (!L_ || num_blocks_ <= 0) return false;
  auto* Ax = static_cast<double*>(A_->x);
  int k = 0;
  for (int b = 0; b < num_blocks_; ++b) {
    const int first = first_entry_of_column_[static_cast<std::size_t>(b)];
    const int last = first_entry_of_column_[static_cast<std::size_t>(b) + 1];
    const Block& D = diagonal_[static_cast<std::size_t>(b)];
    for (int c = 0; c < kBlock; ++c) {
      for (int entry = first; entry < last; ++entry)
        for (int r = 0; r < kBlock; ++r) Ax[k++] = off_[static_cast<std::size_t>(entry)](r, c);
      for (int r = 0; r <= c; ++r) Ax[k++] = D(r, c);
    }
  }
  const int n = kBlock * num_blocks_;
  ArenaScope scope(arena_);
  cholmod_factorize(A_, L_, &common_);
  if (common_.status != CHOLMOD_OK || L_->minor < L_->n) return false;
  B_->nrow = static_cast<std::size_t>(n);
  B_->d = static_cast<std::size_t>(n);
  std::memcpy(B_->x, rhs, sizeof(double) * static_cast<std::size_t>(n));
  if (!cholmod_solve2(CHOLMOD_A, L_, B_, nullptr, &X_, nullptr, &Y_, &E_, &common_)) return false;
  std::memcpy(x, X_->x, sizeof(double) * static_cast<std::size_t>(n));
  return true;
}

template class SparseBlockSolver<6>;
template class SparseBlockSolver<7>;

}  // namespace mcslam::backend
