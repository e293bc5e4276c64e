#pragma once
// CHOLMOD solve of the reduced camera system (6x6 blocks of free poses and extrinsics).
// The block structure goes in through setStructure(), which reruns the symbolic analysis only
// when the structure differs from the last one; solve() is then a numeric factorization and two
// triangular solves. All of CHOLMOD's memory comes from a CholmodArena sized at construction.
#include <cholmod.h>

#include <cstdint>
#include <vector>

#include "cholmod_arena.hpp"

namespace mcslam::backend {

class ReducedSystemSolver {
 public:
  static constexpr int kBlock = 6;

  // max_blocks: most free variables (poses + extrinsics). Dense inputs have leading dimension
  // 6 * max_blocks.
  explicit ReducedSystemSolver(int max_blocks);
  ~ReducedSystemSolver();
  ReducedSystemSolver(const ReducedSystemSolver&) = delete;
  ReducedSystemSolver& operator=(const ReducedSystemSolver&) = delete;

  // pattern[a * max_blocks + b] != 0 for a <= b when block (a, b) is nonzero. Returns true when
  // the structure changed (and was analysed); false when the previous analysis still holds.
  bool setStructure(int num_blocks, const uint8_t* pattern);
  // Factorizes the matrix whose pattern entries are read from the dense, column-major S (upper
  // triangle used) and solves S x = rhs. False when S is not positive definite.
  bool solve(const double* S, const double* rhs, double* x);

  int numBlocks() const { return num_blocks_; }
  int analyses() const { return analyses_; }
  const CholmodArena& arena() const { return arena_; }

 private:
  int max_blocks_;
  int ld_;
  CholmodArena arena_;
  cholmod_common common_;
  cholmod_sparse* A_ = nullptr;
  cholmod_factor* L_ = nullptr;
  cholmod_dense* B_ = nullptr;
  cholmod_dense* X_ = nullptr;
  cholmod_dense* Y_ = nullptr;
  cholmod_dense* E_ = nullptr;
  std::vector<uint8_t> pattern_;  // of the current analysis
  std::vector<int> gather_;       // A->x[k] = S[gather_[k]]
  int num_blocks_ = -1;
  int analyses_ = 0;
};

}  // namespace mcslam::backend
