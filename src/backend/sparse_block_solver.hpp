#pragma once
// CHOLMOD solve of a sparse symmetric system of NxN blocks (6 for SE(3) poses, 7 for Sim(3)): a diagonal block per
// variable and off-diagonal blocks where two variables share a term (the pose graph's edges). The structure goes in
// through setStructure(), which reruns the symbolic analysis only when it differs from the last one; solve() is a
// numeric factorization and two triangular solves. Every buffer, and all of CHOLMOD's memory (a CholmodArena), is sized
// at construction from the most blocks and off-diagonal blocks; nothing is allocated afterwards while the arena
// suffices.
#include <cholmod.h>

#include <cstdint>
#include <span>
#include <vector>

#include "cholmod_arena.hpp"
#include "mcslam/core/se3.hpp"

namespace mcslam::backend {

struct BlockPair {
  int32_t a = 0, b = 0;  // variables, a != b, either order
};

template <int N>
class SparseBlockSolver {
 public:
  static constexpr int kBlock = N;
  using Block = Eigen::Matrix<double, N, N>;

  SparseBlockSolver(int max_blocks, int max_pairs);
  ~SparseBlockSolver();
  SparseBlockSolver(const SparseBlockSolver&) = delete;
  SparseBlockSolver& operator=(const SparseBlockSolver&) = delete;

  // `pairs` (duplicates allowed, at most max_pairs) are the off-diagonal nonzeros; entry_of_pair[k] receives the
  // off-diagonal block entry pair k adds to (offDiagonal()). Returns true when the structure changed and was
  // analysed.
  bool setStructure(int num_blocks, std::span<const BlockPair> pairs, std::span<int32_t> entry_of_pair);

  // The blocks to fill before solve(): diagonal(v) is H_vv; offDiagonal(e) is H_ab of entry e with a < b.
  void setZero();
  Block& diagonal(int v) { return diagonal_[static_cast<std::size_t>(v)]; }
  Block& offDiagonal(int e) { return off_[static_cast<std::size_t>(e)]; }
  const Block& diagonal(int v) const { return diagonal_[static_cast<std::size_t>(v)]; }
  // The lower variable of entry e (its block row).
  int entryLow(int e) const { return entry_low_[static_cast<std::size_t>(e)]; }

  // Solves H x = rhs (N * num_blocks values each). False when H is not positive definite.
  bool solve(const double* rhs, double* x);

  int numBlocks() const { return num_blocks_; }
  int analyses() const { return analyses_; }
  const CholmodArena& arena() const { return arena_; }

 private:
  void buildPattern();

  int max_blocks_, max_pairs_;
  CholmodArena arena_;
  cholmod_common common_;
  cholmod_sparse* A_ = nullptr;
  cholmod_factor* L_ = nullptr;
  cholmod_dense* B_ = nullptr;
  cholmod_dense* X_ = nullptr;
  cholmod_dense* Y_ = nullptr;
  cholmod_dense* E_ = nullptr;
  std::vector<Block> diagonal_;
  std::vector<Block> off_;
  // Structure: entries sorted by (high, low) variable; previous one kept to skip an unchanged analysis.
  std::vector<int64_t> keys_, previous_keys_;  // low + high * max_blocks_
  std::vector<int32_t> order_;                 // scratch: pairs sorted by key
  std::vector<int32_t> entry_low_;
  std::vector<int32_t> first_entry_of_column_;  // per block column: its first entry (entries sorted by column)
  int entries_ = 0, previous_entries_ = -1;
  int num_blocks_ = -1;
  int analyses_ = 0;
};

extern template class SparseBlockSolver<6>;
extern template class SparseBlockSolver<7>;

}  // namespace mcslam::backend
