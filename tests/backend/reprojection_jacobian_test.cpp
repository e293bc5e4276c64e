// The analytic Jacobians of the reprojection residual and the extrinsic prior against central
// differences taken on the same right perturbations, for both distortion models.
#include <gtest/gtest.h>

#include <random>

#include "backend_testkit.hpp"
#include "mcslam/backend/extrinsic_prior.hpp"
#include "mcslam/backend/reprojection_residual.hpp"

using namespace mcslam;
using namespace mcslam::backend;

namespace {

CameraModel radtanCamera() { return testkit::isecRig().model(2); }
CameraModel equidistantCamera() {
  return CameraModel(512, 512, 190.97, 190.97, 254.93, 256.89, Distortion::Equidistant,
                     {0.0034823894022493434, 0.0007150348452162257, -0.0020532361418706202, 0.00020293673591811182});
}
CameraModel pinholeCamera() { return CameraModel(640, 480, 500, 505, 320, 240, Distortion::None); }

struct Case {
  SE3 T_w_b, T_b_c;
  Vec3 p_w;
  Vec2 uv;
};

// A random configuration whose point lies in front of the camera at 1-8 m and projects.
Case randomCase(const CameraModel& cam, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  for (;;) {
    Case c;
    c.T_w_b = SE3(so3Exp(Vec3(u(rng), u(rng), u(rng))), Vec3(u(rng), u(rng), u(rng)) * 3);
    c.T_b_c = SE3(so3Exp(0.3 * Vec3(u(rng), u(rng), u(rng))), Vec3(u(rng), u(rng), u(rng)) * 0.2);
    const Vec3 p_c(u(rng) * 2, u(rng) * 2, 1.5 + 3.5 * (u(rng) + 1));
    c.p_w = c.T_w_b * (c.T_b_c * p_c);
    Vec2 uv;
    if (!cam.project(p_c, uv)) continue;
    c.uv = uv + Vec2(u(rng), u(rng)) * 3;
    return c;
  }
}

template <typename F>
Eigen::MatrixXd numericJacobian(F residual_of_delta, int dim, int rows) {
  const double h = 1e-6;
  Eigen::MatrixXd J(rows, dim);
  for (int i = 0; i < dim; ++i) {
    Eigen::VectorXd d = Eigen::VectorXd::Zero(dim);
    d(i) = h;
    J.col(i) = (residual_of_delta(d) - residual_of_delta(-d)) / (2 * h);
  }
  return J;
}

void checkReprojectionJacobians(const CameraModel& cam, unsigned seed) {
  std::mt19937 rng(seed);
  const double sigma = 1.44;
  for (int trial = 0; trial < 50; ++trial) {
    const Case c = randomCase(cam, rng);
    Vec2 r;
    ReprojectionJacobians J;
    ASSERT_TRUE(reprojectionResidual(cam, c.T_w_b, c.T_b_c, c.p_w, c.uv, sigma, r, &J));
    auto eval = [&](const SE3& T_w_b, const SE3& T_b_c, const Vec3& p) {
      Vec2 out;
      EXPECT_TRUE(reprojectionResidual(cam, T_w_b, T_b_c, p, c.uv, sigma, out));
      return Eigen::VectorXd(out);
    };
    const Eigen::MatrixXd Jp = numericJacobian(
        [&](const Eigen::VectorXd& d) { return eval(c.T_w_b * SE3::exp(Vec6(d)), c.T_b_c, c.p_w); }, 6, 2);
    const Eigen::MatrixXd Je = numericJacobian(
        [&](const Eigen::VectorXd& d) { return eval(c.T_w_b, c.T_b_c * SE3::exp(Vec6(d)), c.p_w); }, 6, 2);
    const Eigen::MatrixXd Jl =
        numericJacobian([&](const Eigen::VectorXd& d) { return eval(c.T_w_b, c.T_b_c, c.p_w + Vec3(d)); }, 3, 2);
    // Relative to the Jacobian's size; central differences are good to ~1e-8 here.
    EXPECT_LT((Jp - J.pose).norm(), 1e-6 * (1 + Jp.norm())) << "pose, trial " << trial;
    EXPECT_LT((Je - J.extrinsic).norm(), 1e-6 * (1 + Je.norm())) << "extrinsic, trial " << trial;
    EXPECT_LT((Jl - J.point).norm(), 1e-6 * (1 + Jl.norm())) << "point, trial " << trial;
    // The residual is the whitened reprojection error.
    Vec2 uv;
    cam.project(c.T_b_c.inverse() * (c.T_w_b.inverse() * c.p_w), uv);
    EXPECT_LT(((uv - c.uv) / sigma - r).norm(), 1e-12);
  }
}

}  // namespace

TEST(ReprojectionJacobian, RadTanMatchesNumeric) { checkReprojectionJacobians(radtanCamera(), 11); }
TEST(ReprojectionJacobian, EquidistantMatchesNumeric) { checkReprojectionJacobians(equidistantCamera(), 12); }
TEST(ReprojectionJacobian, PinholeMatchesNumeric) { checkReprojectionJacobians(pinholeCamera(), 13); }

TEST(ReprojectionJacobian, FailsBehindCamera) {
  const CameraModel cam = pinholeCamera();
  Vec2 r;
  EXPECT_FALSE(reprojectionResidual(cam, SE3(), SE3(), Vec3(0, 0, -2), Vec2(320, 240), 1.0, r));
}

TEST(ExtrinsicPriorJacobian, MatchesNumericAndVanishesAtCalibration) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  const ExtrinsicPriorSigmas sigmas{0.02, 0.01};
  for (int trial = 0; trial < 30; ++trial) {
    const SE3 calib(so3Exp(Vec3(u(rng), u(rng), u(rng))), Vec3(u(rng), u(rng), u(rng)));
    const SE3 T = calib * SE3::exp((Vec6() << 0.05 * u(rng), 0.05 * u(rng), 0.05 * u(rng), 0.2 * u(rng), 0.2 * u(rng),
                                    0.2 * u(rng))
                                       .finished());
    Mat6 J;
    extrinsicPriorResidual(calib, T, sigmas, nullptr, &J);
    const Eigen::MatrixXd Jn = numericJacobian(
        [&](const Eigen::VectorXd& d) {
          return Eigen::VectorXd(extrinsicPriorResidual(calib, T * SE3::exp(Vec6(d)), sigmas));
        },
        6, 6);
    EXPECT_LT((Jn - J).norm(), 1e-6 * (1 + J.norm())) << trial;
    EXPECT_LT(extrinsicPriorResidual(calib, calib, sigmas).norm(), 1e-12);
  }
}

TEST(RobustLoss, WeightIsDerivativeOfRho) {
  for (LossKind kind : {LossKind::Trivial, LossKind::Huber, LossKind::Cauchy}) {
    const RobustLoss loss{kind, 2.0};
    for (double s : {0.1, 1.0, 3.9, 4.1, 10.0, 400.0}) {
      double rho, w;
      loss.evaluate(s, rho, w);
      const double h = 1e-6 * s;
      EXPECT_NEAR(w, (loss.rho(s + h) - loss.rho(s - h)) / (2 * h), 1e-6) << int(kind) << " s=" << s;
    }
  }
  // Huber: quadratic inside the threshold, linear in |r| outside.
  const RobustLoss huber{LossKind::Huber, 2.0};
  EXPECT_DOUBLE_EQ(huber.rho(3.0), 3.0);
  EXPECT_DOUBLE_EQ(huber.rho(36.0), 2 * 2.0 * 6.0 - 4.0);
}
