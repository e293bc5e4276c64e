#include <gtest/gtest.h>

#include <random>

#include "mcslam/core/se3.hpp"

using namespace mcslam;

namespace {
Vec6 randomTangent(std::mt19937& rng, double scale) {
  std::normal_distribution<double> n(0.0, scale);
  Vec6 xi;
  for (int i = 0; i < 6; ++i) xi[i] = n(rng);
  return xi;
}
}  // namespace

TEST(SE3, ExpLogRoundTrip) {
  std::mt19937 rng(1);
  for (int i = 0; i < 200; ++i) {
    const Vec6 xi = randomTangent(rng, 0.8);
    const Vec6 back = SE3::exp(xi).log();
    EXPECT_LT((xi - back).norm(), 1e-9) << xi.transpose();
  }
  // Near pi and near zero.
  Vec6 xi = Vec6::Zero();
  xi[3] = M_PI - 1e-7;
  EXPECT_NEAR(SE3::exp(xi).log()[3], M_PI - 1e-7, 1e-6);
  xi.setConstant(1e-10);
  EXPECT_LT((SE3::exp(xi).log() - xi).norm(), 1e-15);
}

TEST(SE3, ComposeInverseAndAdjoint) {
  std::mt19937 rng(2);
  const SE3 A = SE3::exp(randomTangent(rng, 1.0));
  const SE3 B = SE3::exp(randomTangent(rng, 1.0));
  const Vec3 p(0.3, -1.2, 2.0);
  EXPECT_LT(((A * B) * p - A * (B * p)).norm(), 1e-12);
  EXPECT_LT(((A * A.inverse()).matrix() - Mat4::Identity()).norm(), 1e-12);
  const Vec6 xi = randomTangent(rng, 0.5);
  const SE3 lhs = SE3::exp(A.adjoint() * xi);
  const SE3 rhs = A * SE3::exp(xi) * A.inverse();
  EXPECT_LT((lhs.matrix() - rhs.matrix()).norm(), 1e-10);
}

TEST(SO3, RightJacobianMatchesNumeric) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const Vec3 w(n(rng), n(rng), n(rng));
    const Mat3 Jr = so3RightJacobian(w);
    for (int k = 0; k < 3; ++k) {
      Vec3 dw = Vec3::Zero();
      dw[k] = 1e-6;
      // exp(w + dw) = exp(w) exp(Jr dw)  =>  log(exp(w)^T exp(w + dw)) / 1e-6 = Jr e_k
      const Vec3 col = so3Log(so3Exp(w).transpose() * so3Exp(w + dw)) / 1e-6;
      EXPECT_LT((col - Jr.col(k)).norm(), 1e-5);
    }
    EXPECT_LT((so3LeftJacobianInverse(w) * so3LeftJacobian(w) - Mat3::Identity()).norm(), 1e-9);
  }
}
