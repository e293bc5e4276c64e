// The Schur accumulator against a dense solve of the whole system: random point-and-block problems.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <random>
#include <vector>

#include "mcslam/backend/schur_accumulator.hpp"

namespace {

using mcslam::Mat3;
using mcslam::Vec3;
using mcslam::backend::SchurAccumulator;

// Residuals of 2 rows, each touching one point and one or two blocks (a pose, and maybe an extrinsic).
struct Problem {
  int blocks = 4, points = 12;
  struct Row {
    int point, block, block2;  // block2 < 0: none
    Eigen::Matrix<double, 2, 3> Jp;
    Eigen::Matrix<double, 2, 6> Jb, Jb2;
    Eigen::Vector2d r;
  };
  std::vector<Row> rows;
  explicit Problem(unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    auto fill = [&](auto& m) {
      for (int i = 0; i < m.size(); ++i) m.data()[i] = u(rng);
    };
    for (int p = 0; p < points; ++p) {
      for (int k = 0; k < 4; ++k) {  // one block may be observed twice: entries of one block then sum
        Row row;
        row.point = p;
        row.block = static_cast<int>(rng() % blocks);
        row.block2 = k % 2 ? static_cast<int>(rng() % blocks) : -1;
        if (row.block2 == row.block) row.block2 = -1;
        fill(row.Jp);
        fill(row.Jb);
        fill(row.Jb2);
        fill(row.r);
        rows.push_back(row);
      }
    }
  }
  int dim() const { return 6 * blocks + 3 * points; }
  // The full normal equations, blocks first, then points.
  void dense(Eigen::MatrixXd& H, Eigen::VectorXd& g) const {
    H.setZero(dim(), dim());
    g.setZero(dim());
    for (const Row& row : rows) {
      Eigen::MatrixXd J = Eigen::MatrixXd::Zero(2, dim());
      J.middleCols<6>(6 * row.block) += row.Jb;
      if (row.block2 >= 0) J.middleCols<6>(6 * row.block2) += row.Jb2;
      J.middleCols<3>(6 * blocks + 3 * row.point) = row.Jp;
      H += J.transpose() * J;
      g += J.transpose() * row.r;
    }
    H.diagonal().array() += 1e-3;  // full rank
  }
};

// The reduced system by the accumulator; merged couplings or one entry per row.
void reduced(const Problem& pb, bool merged, bool upper, Eigen::MatrixXd& S, Eigen::VectorXd& r) {
  const int n = 6 * pb.blocks;
  S.setZero(n, n);
  r.setZero(n);
  std::vector<uint8_t> pattern(static_cast<size_t>(pb.blocks * pb.blocks), 0);
  SchurAccumulator acc(pb.blocks, 16);
  for (int p = 0; p < pb.points; ++p) {
    Mat3 Hpp = Mat3::Identity() * 1e-3;
    Vec3 gp = Vec3::Zero();
    acc.beginPoint();
    for (const Problem::Row& row : pb.rows) {
      if (row.point != p) continue;
      Hpp += row.Jp.transpose() * row.Jp;
      gp += row.Jp.transpose() * row.r;
      auto add = [&](int block, const Eigen::Matrix<double, 2, 6>& Jb) {
        const Eigen::Matrix<double, 6, 3> W = Jb.transpose() * row.Jp;
        if (merged) {
          acc.coupling(block) += W;
        } else {
          acc.appendCoupling(block) = W;
        }
        S.block<6, 6>(6 * block, 6 * block) += Jb.transpose() * Jb;
        r.segment<6>(6 * block) += Jb.transpose() * row.r;
      };
      add(row.block, row.Jb);
      if (row.block2 >= 0) {
        add(row.block2, row.Jb2);
        const int a = std::min(row.block, row.block2), b = std::max(row.block, row.block2);
        const auto& Ja = a == row.block ? row.Jb : row.Jb2;
        const auto& Jc = a == row.block ? row.Jb2 : row.Jb;
        S.block<6, 6>(6 * a, 6 * b) += Ja.transpose() * Jc;
        if (!upper) S.block<6, 6>(6 * b, 6 * a) += Jc.transpose() * Ja;
      }
    }
    const Mat3 H_inv = Hpp.inverse();
    if (upper) {
      acc.eliminate(H_inv, gp, S, r, pattern.data(), pb.blocks);
    } else {
      acc.eliminate(H_inv, gp, S, r);
    }
  }
  if (upper) S = S.selfadjointView<Eigen::Upper>();
  S.diagonal().array() += 1e-3;
}

class SchurAccumulatorTest : public ::testing::TestWithParam<std::tuple<bool, bool>> {};

TEST_P(SchurAccumulatorTest, ReducedSolveEqualsTheDenseSolve) {
  const auto [merged, upper] = GetParam();
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Problem pb(seed);
    Eigen::MatrixXd H, S;
    Eigen::VectorXd g, r;
    pb.dense(H, g);
    reduced(pb, merged, upper, S, r);
    const Eigen::VectorXd x = H.ldlt().solve(-g);
    const Eigen::VectorXd xc = S.ldlt().solve(-r);
    ASSERT_EQ(xc.size(), 6 * pb.blocks);
    EXPECT_LT((xc - x.head(6 * pb.blocks)).norm(), 1e-8 * (1 + x.norm())) << "seed " << seed;
    // The reduced matrix is the Schur complement H_cc - H_cp H_pp^-1 H_pc.
    const int n = 6 * pb.blocks, m = 3 * pb.points;
    const Eigen::MatrixXd Sc = H.topLeftCorner(n, n) - H.topRightCorner(n, m) * H.bottomRightCorner(m, m).ldlt().solve(
                                                                                    H.bottomLeftCorner(m, n));
    EXPECT_LT((S - Sc).norm(), 1e-9 * Sc.norm()) << "seed " << seed;
  }
}

INSTANTIATE_TEST_SUITE_P(Modes, SchurAccumulatorTest, ::testing::Combine(::testing::Bool(), ::testing::Bool()));

TEST(SchurAccumulator, PatternMarksTheUpperBlocksAPointLinks) {
  SchurAccumulator acc(4, 4);
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(24, 24);
  Eigen::VectorXd r = Eigen::VectorXd::Zero(24);
  std::vector<uint8_t> pattern(16, 0);
  acc.beginPoint();
  acc.coupling(3).setOnes();
  acc.coupling(1).setOnes();
  acc.coupling(3).setOnes();  // the same block again: no new coupling
  EXPECT_EQ(acc.numCouplings(), 2);
  acc.eliminate(Mat3::Identity(), Vec3::Ones(), S, r, pattern.data(), 4);
  const std::vector<uint8_t> expected = {0, 0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 0, 0, 0, 1};
  EXPECT_EQ(pattern, expected);
  EXPECT_EQ((S.block<6, 6>(18, 6).norm()), 0.0);  // lower block untouched
  acc.beginPoint();
  EXPECT_EQ(acc.numCouplings(), 0);
  EXPECT_EQ(acc.coupling(3).norm(), 0.0);  // a new point starts from zero
}

}  // namespace
