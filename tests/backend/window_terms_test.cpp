// Each extra term of the window (calibration prior, marginalization prior, scale hold): what it adds to the
// camera system (gradient J^T r, Gauss-Newton matrix J^T J, diagonal) against numeric derivatives of its cost.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "backend_testkit.hpp"
#include "calibration_prior.hpp"
#include "marginalization_prior.hpp"
#include "window_scale_hold.hpp"

namespace {

using namespace mcslam;
using namespace mcslam::backend;

constexpr double kStep = 1e-6;

// A window of four keyframes of the 5-camera rig, extrinsics 1..4 refined; every variable one block:
// poses 0..3 (keyframe 0 held), extrinsics after them.
struct Fixture {
  SolverOptions options = [] {
    SolverOptions o;
    o.refine_extrinsics = true;
    return o;
  }();
  WindowStorage window{testkit::isecRig(), WindowCapacity{4, 16, 64}, options};
  std::vector<int> pose_block, ext_block;
  std::vector<uint8_t> use_fej;
  std::vector<SE3> kf_trial, ext_trial;
  std::vector<Vec6> ext_d_trial;
  int blocks = 0;

  Fixture() {
    std::mt19937 rng(7);
    std::normal_distribution<double> n(0, 1);
    auto random6 = [&](double s) {
      Vec6 v;
      for (int i = 0; i < 6; ++i) v(i) = s * n(rng);
      return v;
    };
    for (int k = 0; k < 4; ++k) {
      window.addKeyframe(k, SE3::exp(random6(0.5) + (Vec6() << 0.8 * k, 0.1 * k, 0, 0, 0.2 * k, 0).finished()));
    }
    for (int c = 1; c < window.numCameras(); ++c) {  // off the calibration; not linked to a prior: d = 0
      ExtrinsicState& e = window.extrinsics[c];
      e.T = e.T_lin = e.T_calib * SE3::exp(random6(0.01));
    }
    pose_block.assign(4, -1);
    for (int s = 0; s < 4; ++s) {
      if (window.keyframes[s].id != 0) pose_block[s] = blocks++;
    }
    ext_block.assign(window.numCameras(), -1);
    for (int c = 1; c < window.numCameras(); ++c) ext_block[c] = blocks++;
    use_fej.assign(window.numCameras(), 0);
    resetTrial();
  }
  void resetTrial() {
    kf_trial.clear();
    for (const KeyframeState& kf : window.keyframes) kf_trial.push_back(kf.T_w_b);
    ext_trial.clear();
    ext_d_trial.clear();
    for (const ExtrinsicState& e : window.extrinsics) {
      ext_trial.push_back(e.T);
      ext_d_trial.push_back(e.d);
    }
  }
  WindowVariables variables() const {
    return {window, pose_block, ext_block, use_fej, kf_trial, ext_trial, ext_d_trial};
  }
  // The trial state moved by x along coordinate i of the stacked variables (right perturbation, as the solver).
  void moveTrial(int i, double x) {
    resetTrial();
    const int b = i / 6;
    Vec6 delta = Vec6::Zero();
    delta(i % 6) = x;
    for (int s = 0; s < 4; ++s) {
      if (pose_block[s] == b) kf_trial[s] = window.keyframes[s].T_w_b * SE3::exp(delta);
    }
    for (int c = 0; c < window.numCameras(); ++c) {
      if (ext_block[c] != b) continue;
      const ExtrinsicState& e = window.extrinsics[c];
      ext_d_trial[c] = e.d + delta;
      ext_trial[c] = e.T_lin * SE3::exp(ext_d_trial[c]);
    }
  }
  double trialCost(const WindowTerm& term, int i, double x) {
    moveTrial(i, x);
    double cost = 0;
    term.addCost(variables(), true, cost);
    resetTrial();
    return cost;
  }
  // What the term adds to an empty system.
  void system(WindowTerm& term, Eigen::MatrixXd& S, Eigen::VectorXd& g, Eigen::VectorXd& D) {
    const int n = 6 * blocks;
    S.setZero(n, n);
    g.setZero(n);
    D.setZero(n);
    std::vector<uint8_t> pattern(static_cast<size_t>(blocks * blocks), 0);
    for (int a = 0; a < blocks; ++a) pattern[a * blocks + a] = 1;  // as the linearization marks them
    CameraSystem sys{S, g, D, pattern.data(), blocks};
    term.linearize(variables());
    term.addToSystem(variables(), sys);
    for (int a = 0; a < blocks; ++a) {
      for (int b = 0; b < blocks; ++b) {
        if (b < a) {
          EXPECT_EQ(pattern[a * blocks + b], 0) << "lower blocks stay empty";
        }
        if (S.block<6, 6>(6 * a, 6 * b).norm() > 0) {
          EXPECT_EQ(pattern[a * blocks + b], 1) << a << "," << b;
        }
      }
    }
    S = S.selfadjointView<Eigen::Upper>();
  }
  Eigen::VectorXd numericGradient(const WindowTerm& term) {
    Eigen::VectorXd g(6 * blocks);
    for (int i = 0; i < 6 * blocks; ++i) g(i) = (trialCost(term, i, kStep) - trialCost(term, i, -kStep)) / (2 * kStep);
    return g;
  }
  Eigen::MatrixXd numericHessian(const WindowTerm& term) {
    const int n = 6 * blocks;
    Eigen::MatrixXd H(n, n);
    const double h = 1e-4;
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        auto at = [&](double xi, double xj) {
          resetTrial();
          // Both coordinates moved: compose the two single moves (they act on different or the same block).
          moveTrial(i, xi);
          const std::vector<SE3> kf1 = kf_trial, ext1 = ext_trial;
          const std::vector<Vec6> d1 = ext_d_trial;
          moveTrial(j, xj);
          for (size_t s = 0; s < kf_trial.size(); ++s) {
            if (pose_block[s] == i / 6 && pose_block[s] == j / 6) {
              Vec6 d = Vec6::Zero();
              d(i % 6) += xi;
              d(j % 6) += xj;
              kf_trial[s] = window.keyframes[s].T_w_b * SE3::exp(d);
            } else if (pose_block[s] == i / 6) {
              kf_trial[s] = kf1[s];
            }
          }
          for (size_t c = 0; c < ext_trial.size(); ++c) {
            if (ext_block[c] == i / 6 && ext_block[c] == j / 6) {
              ext_d_trial[c] = window.extrinsics[c].d;
              ext_d_trial[c](i % 6) += xi;
              ext_d_trial[c](j % 6) += xj;
              ext_trial[c] = window.extrinsics[c].T_lin * SE3::exp(ext_d_trial[c]);
            } else if (ext_block[c] == i / 6) {
              ext_trial[c] = ext1[c];
              ext_d_trial[c] = d1[c];
            }
          }
          double cost = 0;
          term.addCost(variables(), true, cost);
          return cost;
        };
        H(i, j) = (at(h, h) - at(h, -h) - at(-h, h) + at(-h, -h)) / (4 * h * h);
      }
    }
    resetTrial();
    return H;
  }
};

void expectNear(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double tol, const char* what) {
  EXPECT_LT((a - b).norm(), tol * (1 + b.norm())) << what << "\n" << a << "\n---\n" << b;
}

TEST(WindowTerms, CalibrationPriorGradientAndMatrixMatchNumericDerivatives) {
  Fixture f;
  CalibrationPrior term(f.window.numCameras(), f.options.extrinsic_prior);
  Eigen::MatrixXd S;
  Eigen::VectorXd g, D;
  f.system(term, S, g, D);
  double cost = 0;
  term.addCost(f.variables(), false, cost);
  EXPECT_GT(cost, 0);
  expectNear(g, f.numericGradient(term), 1e-6, "gradient");
  EXPECT_LT((D - S.diagonal()).norm(), 1e-9 * S.norm());
  // At the calibration the residual is zero: J^T J is then the cost's Hessian.
  for (ExtrinsicState& e : f.window.extrinsics) {
    e.T = e.T_lin = e.T_calib;
    e.d.setZero();
  }
  f.resetTrial();
  f.system(term, S, g, D);
  EXPECT_LT(g.norm(), 1e-12);
  expectNear(S, f.numericHessian(term), 1e-5, "J^T J");
}

TEST(WindowTerms, CalibrationPriorUsesTheFirstEstimateJacobianWhenAsked) {
  Fixture f;
  CalibrationPrior term(f.window.numCameras(), f.options.extrinsic_prior);
  Eigen::MatrixXd S, S_fej;
  Eigen::VectorXd g, g_fej, D;
  f.system(term, S, g, D);
  for (int c = 1; c < f.window.numCameras(); ++c) {  // linked to a prior at another estimate
    f.use_fej[c] = 1;
    ExtrinsicState& e = f.window.extrinsics[c];
    e.T_lin = e.T * SE3::exp((Vec6() << 0, 0, 0, 0.05, -0.03, 0.02).finished());
  }
  f.system(term, S_fej, g_fej, D);
  EXPECT_GT((g - g_fej).norm(), 1e-6 * g.norm()) << "J^T r, with r at the current estimate";
  EXPECT_GT((S - S_fej).norm(), 1e-6 * S.norm()) << "the Jacobian moved to T_lin";
  for (int c = 1; c < f.window.numCameras(); ++c) f.window.extrinsics[c].calibration_prior = false;
  f.system(term, S, g, D);
  EXPECT_EQ(S.norm(), 0.0);
  double cost = 0;
  term.addCost(f.variables(), false, cost);
  EXPECT_EQ(cost, 0.0);
}

TEST(WindowTerms, MarginalizationPriorGradientAndMatrixAreItsQuadratic) {
  Fixture f;
  MarginalizationPrior term(f.window);
  ASSERT_EQ(term.dim(), 24);
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0, 1);
  Eigen::MatrixXd A(24, 24);
  for (int i = 0; i < A.size(); ++i) A.data()[i] = n(rng);
  term.H = A * A.transpose();
  for (int i = 0; i < 24; ++i) term.b(i) = n(rng);
  term.c = 2.0;
  term.empty = false;
  for (int c = 1; c < f.window.numCameras(); ++c) {  // linked extrinsics away from their linearization point
    ExtrinsicState& e = f.window.extrinsics[c];
    for (int i = 0; i < 6; ++i) e.d(i) = 0.01 * n(rng);
    e.T = e.T_lin * SE3::exp(e.d);
  }
  f.resetTrial();
  Eigen::MatrixXd S;
  Eigen::VectorXd g, D;
  f.system(term, S, g, D);
  expectNear(g, f.numericGradient(term), 1e-6, "gradient");
  // Extrinsics come after the three free poses: the prior fills that corner exactly.
  const int k = 18;
  expectNear(S.bottomRightCorner(24, 24), term.H, 1e-12, "matrix");
  EXPECT_EQ(S.topLeftCorner(k, k).norm(), 0.0);
  expectNear(D.tail(24), term.H.diagonal(), 1e-12, "diagonal");
  expectNear(S, f.numericHessian(term), 1e-5, "Hessian");
}

TEST(WindowTerms, MarginalizationPriorForgetsAnExtrinsicByItsSchurComplement) {
  Fixture f;
  MarginalizationPrior term(f.window);
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0, 1);
  Eigen::MatrixXd A(24, 24);
  for (int i = 0; i < A.size(); ++i) A.data()[i] = n(rng);
  term.H = A * A.transpose();
  const Eigen::MatrixXd H = term.H;
  term.empty = false;
  f.window.extrinsics[2].in_prior = true;
  term.forgetExtrinsic(2, f.window);  // variable 1: rows 6..11
  EXPECT_FALSE(f.window.extrinsics[2].in_prior);
  EXPECT_EQ((term.H.middleRows<6>(6).norm()), 0.0);
  const Eigen::MatrixXd expected = H - H.middleCols<6>(6) * H.block<6, 6>(6, 6).inverse() * H.middleRows<6>(6);
  Eigen::MatrixXd got = term.H;
  got.middleRows<6>(6).setZero();
  Eigen::MatrixXd want = expected;
  want.middleRows<6>(6).setZero();
  want.middleCols<6>(6).setZero();
  expectNear(got, want, 1e-9, "Schur complement");
}

TEST(WindowTerms, ScaleHoldGradientAndMatrixMatchNumericDerivatives) {
  Fixture f;
  WindowScaleHold term(4);
  term.prepare(f.window, true);
  ASSERT_TRUE(term.active());
  // Move the held keyframes (1 and 2; 0 is the anchor, 3 the newest) so that the residual is not zero.
  for (int s = 1; s <= 2; ++s) f.window.keyframes[s].T_w_b.t *= 1.01;
  f.resetTrial();
  Eigen::MatrixXd S;
  Eigen::VectorXd g, D;
  f.system(term, S, g, D);
  double cost = 0;
  term.addCost(f.variables(), false, cost);
  ASSERT_GT(cost, 1.0);
  const Eigen::VectorXd g_num = f.numericGradient(term);
  expectNear(g, g_num, 1e-5, "gradient");
  // One residual: J^T J = g g^T / r^2 with r^2 = 2 cost.
  expectNear(S, g_num * g_num.transpose() / (2 * cost), 1e-5, "J^T J");
  EXPECT_EQ((g.segment<6>(6 * f.pose_block[3]).norm()), 0.0) << "the newest keyframe is free of it";
  EXPECT_LT((D - S.diagonal()).norm(), 1e-9 * S.norm());
}

TEST(WindowTerms, ScaleHoldStaysOffWithoutHeldKeyframes) {
  SolverOptions o;
  WindowStorage window(testkit::isecRig(), WindowCapacity{4, 16, 64}, o);
  window.addKeyframe(0, SE3());
  window.addKeyframe(1, SE3::exp((Vec6() << 1, 0, 0, 0, 0, 0).finished()));
  WindowScaleHold term(4);
  term.prepare(window, true);
  EXPECT_FALSE(term.active());  // two keyframes: the anchor and the newest, nothing held
  term.prepare(window, false);
  EXPECT_FALSE(term.active());
}

}  // namespace
