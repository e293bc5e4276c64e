// Sim(3): exp and log invert each other (also for large scales and rotations near pi), composition and inverse
// act on points as similarities, the adjoint moves a perturbation across a pose, and with no scale it is SE(3).
#include <gtest/gtest.h>

#include <random>

#include "mcslam/core/sim3.hpp"

using namespace mcslam;

namespace {
Vec7 randomTangent(std::mt19937& rng, double scale) {
  std::normal_distribution<double> n(0.0, scale);
  Vec7 xi;
  for (int i = 0; i < 7; ++i) xi[i] = n(rng);
  return xi;
}
}  // namespace

TEST(Sim3, ExpLogRoundTrip) {
  std::mt19937 rng(1);
  for (int i = 0; i < 200; ++i) {
    const Vec7 xi = randomTangent(rng, 0.8);
    const Vec7 back = Sim3::exp(xi).log();
    EXPECT_LT((xi - back).norm(), 1e-9) << xi.transpose();
  }
  Vec7 xi = Vec7::Zero();
  xi << 1.0, -2.0, 0.5, 0.0, M_PI - 1e-6, 0.0, std::log(8.0);  // near a half turn, eight times larger
  EXPECT_LT((Sim3::exp(xi).log() - xi).norm(), 1e-6);
  xi.setConstant(1e-10);
  EXPECT_LT((Sim3::exp(xi).log() - xi).norm(), 1e-15);
}

TEST(Sim3, ExpIsTheMatrixExponential) {
  // exp of the 4x4 generator [sigma I + hat(phi), rho; 0 0], summed as a plain series.
  std::mt19937 rng(2);
  for (int i = 0; i < 20; ++i) {
    const Vec7 xi = randomTangent(rng, 0.7);
    Mat4 X = Mat4::Zero();
    X.topLeftCorner<3, 3>() = xi[6] * Mat3::Identity() + hat(xi.segment<3>(3));
    X.topRightCorner<3, 1>() = xi.head<3>();
    Mat4 E = Mat4::Identity(), term = Mat4::Identity();
    for (int k = 1; k < 60; ++k) {
      term = term * X / k;
      E += term;
    }
    const Sim3 S = Sim3::exp(xi);
    EXPECT_LT((S.s * S.R - E.topLeftCorner<3, 3>()).norm(), 1e-12);
    EXPECT_LT((S.t - E.topRightCorner<3, 1>()).norm(), 1e-12);
  }
}

TEST(Sim3, ComposeInverseAndAdjoint) {
  std::mt19937 rng(3);
  const Sim3 A = Sim3::exp(randomTangent(rng, 1.0));
  const Sim3 B = Sim3::exp(randomTangent(rng, 1.0));
  const Vec3 p(0.3, -1.2, 2.0);
  EXPECT_LT(((A * B) * p - A * (B * p)).norm(), 1e-12);
  EXPECT_LT((A.inverse() * (A * p) - p).norm(), 1e-12);
  EXPECT_NEAR((A * B).s, A.s * B.s, 1e-15);
  const Vec7 xi = randomTangent(rng, 0.5);
  const Sim3 lhs = Sim3::exp(A.adjoint() * xi);
  const Sim3 rhs = A * Sim3::exp(xi) * A.inverse();
  EXPECT_LT((lhs.R - rhs.R).norm(), 1e-9);
  EXPECT_LT((lhs.t - rhs.t).norm(), 1e-9);
  EXPECT_NEAR(lhs.s, rhs.s, 1e-12);
}

TEST(Sim3, SmallAdjointIsTheBracket) {
  // d/dh [exp(h xi) exp(zeta) exp(-h xi)] at h = 0 is ad(xi) zeta for small zeta.
  std::mt19937 rng(4);
  const Vec7 xi = randomTangent(rng, 0.5);
  const Vec7 zeta = randomTangent(rng, 1e-4);
  const double h = 1e-4;
  const Vec7 moved = (Sim3::exp(h * xi) * Sim3::exp(zeta) * Sim3::exp(-h * xi)).log();
  const Vec7 predicted = zeta + h * (Sim3::smallAdjoint(xi) * zeta);
  EXPECT_LT((moved - predicted).norm(), 1e-9);
}

TEST(Sim3, WithoutScaleItIsSE3) {
  std::mt19937 rng(5);
  for (int i = 0; i < 20; ++i) {
    Vec7 xi = randomTangent(rng, 0.8);
    xi[6] = 0;
    const SE3 T = SE3::exp(xi.head<6>());
    const Sim3 S = Sim3::exp(xi);
    EXPECT_LT((S.R - T.R).norm(), 1e-12);
    EXPECT_LT((S.t - T.t).norm(), 1e-12);
    EXPECT_EQ(S.s, 1.0);
    const Mat7 A = S.adjoint();
    EXPECT_LT((A.topLeftCorner<6, 6>() - T.adjoint()).norm(), 1e-12);
  }
}
