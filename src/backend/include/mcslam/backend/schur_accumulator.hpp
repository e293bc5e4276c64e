#pragma once
// Elimination of point blocks (3 parameters: a landmark) from normal equations whose other variables come in
// blocks of 6 (poses, extrinsics), one point at a time. For a point p with information H_pp, gradient g_p and
// couplings W_a = H_{a,p} with the blocks a it touches, the reduced system over the blocks receives
//
//   S_ab -= W_a H_pp^-1 W_b^T,    r_a -= W_a H_pp^-1 g_p,
//
// H_pp^-1 as the caller formed it (damped or not). The caller adds the blocks' own terms (J^T J, J^T r) to S
// and r directly. Scratch sized at construction: allocates nothing.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "mcslam/core/se3.hpp"

namespace mcslam::backend {

class SchurAccumulator {
 public:
  using Coupling = Eigen::Matrix<double, 6, 3>;
  static constexpr int kBlock = 6;

  // max_blocks: block indices are below it; max_couplings: most couplings one point may have.
  SchurAccumulator(int max_blocks, int max_couplings)
      : slot_of_(static_cast<size_t>(max_blocks), -1),
        W_(static_cast<size_t>(max_couplings)),
        block_(static_cast<size_t>(max_couplings)) {}

  // Starts the next point: no couplings.
  void beginPoint() {
    for (int t = 0; t < count_; ++t) slot_of_[block_[t]] = -1;
    count_ = 0;
  }
  // The point's coupling with `block`, zero when the point first meets it: couplings of one block are summed.
  Coupling& coupling(int block) {
    int t = slot_of_[block];
    if (t < 0) {
      t = count_++;
      slot_of_[block] = t;
      block_[t] = block;
      W_[t].setZero();
    }
    return W_[t];
  }
  // A coupling entry of its own for `block` (the caller sets it): several may name one block, and every pair's
  // product is formed. Not to be mixed with coupling() for one point.
  Coupling& appendCoupling(int block) {
    block_[count_] = block;
    return W_[count_++];
  }
  bool full() const { return count_ >= static_cast<int>(W_.size()); }
  int numCouplings() const { return count_; }

  // Subtracts the current point's W H_inv W^T from S (6x6 blocks at 6 * block) and W H_inv g from r. With a
  // pattern (row-major, `stride` blocks per row), only blocks a <= b are formed and marked there; without, all.
  template <class Matrix, class Vector>
  void eliminate(const Mat3& H_inv, const Vec3& g, Matrix& S, Vector& r, uint8_t* pattern = nullptr,
                 int stride = 0) const {
    for (int ta = 0; ta < count_; ++ta) {
      const int a = block_[ta];
      const Coupling V = W_[ta] * H_inv;
      r.template segment<kBlock>(kBlock * a).noalias() -= V * g;
      for (int tb = 0; tb < count_; ++tb) {
        const int b = block_[tb];
        if (pattern && a > b) continue;
        S.template block<kBlock, kBlock>(kBlock * a, kBlock * b).noalias() -= V * W_[tb].transpose();
        if (pattern) pattern[static_cast<size_t>(a) * stride + b] = 1;
      }
    }
  }

 private:
  std::vector<int> slot_of_;  // per block: its coupling of the current point (-1: none)
  std::vector<Coupling> W_;
  std::vector<int> block_;
  int count_ = 0;
};

}  // namespace mcslam::backend
