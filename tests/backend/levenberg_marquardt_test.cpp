// The damped least-squares loop on a problem with a known minimum: fitting y = a exp(b x) to exact samples.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <vector>

#include "mcslam/backend/levenberg_marquardt.hpp"

namespace {

using mcslam::backend::DampingPolicy;
using mcslam::backend::LeastSquaresProblem;
using mcslam::backend::LoopOptions;
using mcslam::backend::LoopSummary;
using mcslam::backend::minimize;

constexpr double kA = 2.0, kB = 0.7;

// Dense normal equations of the curve fit, damped by Marquardt's clamped diagonal.
class CurveFit final : public LeastSquaresProblem {
 public:
  explicit CurveFit(Eigen::Vector2d start) : x_(start) {
    for (int i = 0; i < 20; ++i) {
      t_.push_back(0.1 * i);
      y_.push_back(kA * std::exp(kB * t_.back()));  // as the model computes it: zero residuals at (kA, kB)
    }
  }
  bool linearize() override {
    H_.setZero();
    g_.setZero();
    cost_ = costAt(x_);
    for (size_t i = 0; i < t_.size(); ++i) {
      const double e = std::exp(x_(1) * t_[i]);
      const Eigen::Vector2d J(e, x_(0) * t_[i] * e);
      H_ += J * J.transpose();
      g_ += J * (x_(0) * e - y_[i]);
    }
    ++linearizations;
    return true;
  }
  double cost() const override { return cost_; }
  void buildDampedSystem(double damping) override {
    mu_ = damping;
    A_ = H_;
    for (int i = 0; i < 2; ++i) A_(i, i) += mu_ * std::clamp(H_(i, i), 1e-6, 1e32);
  }
  double maxGradient() const override { return g_.cwiseAbs().maxCoeff(); }
  bool solveStep() override {
    dx_ = A_.ldlt().solve(-g_);
    return dx_.allFinite();
  }
  double stepNorm() const override { return dx_.norm(); }
  double stateNorm() const override { return x_.norm(); }
  double modelCostDecrease(double) const override { return -(g_.dot(dx_) + 0.5 * dx_.dot(H_ * dx_)); }
  bool evaluateTrial(double& cost) override {
    cost = costAt(x_ + dx_);
    trial_costs.push_back(cost);
    return std::isfinite(cost);
  }
  void acceptTrial() override {
    x_ += dx_;
    cost_ = trial_costs.back();
  }
  void rejectTrial() override { ++rejections; }

  double costAt(const Eigen::Vector2d& x) const {
    double c = 0;
    for (size_t i = 0; i < t_.size(); ++i) c += 0.5 * std::pow(x(0) * std::exp(x(1) * t_[i]) - y_[i], 2);
    return c;
  }
  const Eigen::Vector2d& x() const { return x_; }

  int linearizations = 0, rejections = 0;
  std::vector<double> trial_costs;

 private:
  Eigen::Vector2d x_;
  std::vector<double> t_, y_;
  double cost_ = 0, mu_ = 0;
  Eigen::Matrix2d H_, A_;
  Eigen::Vector2d g_, dx_;
};

LoopOptions tolerances(LoopOptions o) {
  o.max_solves = 200;
  o.gradient_tolerance = 1e-14;
  o.parameter_tolerance = 1e-14;
  o.function_tolerance = 0;
  return o;
}

TEST(LevenbergMarquardt, TrustRegionFindsTheMinimumAndRefusesAnOvershoot) {
  // From a = 10, b = -1 Gauss-Newton with a wide radius overshoots: the first trial raises the cost.
  CurveFit fit({10.0, -1.0});
  LoopOptions o;
  o.damping = DampingPolicy::trustRegion(1e8);
  const double start = fit.costAt(fit.x());
  const LoopSummary s = minimize(fit, tolerances(o));
  ASSERT_FALSE(fit.trial_costs.empty());
  EXPECT_GT(fit.trial_costs.front(), start) << "the first, undamped step must overshoot";
  EXPECT_GE(fit.rejections, 1);
  // Each solve was taken or refused, but for a last one that converged by the parameter tolerance.
  EXPECT_GE(s.steps + fit.rejections, s.solves - 1);
  EXPECT_LE(s.steps + fit.rejections, s.solves);
  EXPECT_EQ(fit.linearizations, 1 + s.steps);  // only taken steps are linearized again
  EXPECT_TRUE(s.converged);
  EXPECT_NEAR(fit.x()(0), kA, 1e-8);
  EXPECT_NEAR(fit.x()(1), kB, 1e-8);
  EXPECT_LT(s.final_cost, 1e-16);
  EXPECT_DOUBLE_EQ(s.initial_cost, start);
}

TEST(LevenbergMarquardt, MarquardtLambdaFindsTheMinimumAndRefusesAnOvershoot) {
  CurveFit fit({10.0, -1.0});
  LoopOptions o;
  o.damping = DampingPolicy::multiplicative(1e-8, 0.2, 10.0, 1e-12, 1e12);
  const double start = fit.costAt(fit.x());
  const LoopSummary s = minimize(fit, tolerances(o));
  ASSERT_FALSE(fit.trial_costs.empty());
  EXPECT_GT(fit.trial_costs.front(), start);
  EXPECT_GE(fit.rejections, 1);
  EXPECT_NEAR(fit.x()(0), kA, 1e-8);
  EXPECT_NEAR(fit.x()(1), kB, 1e-8);
  // Every taken step lowered the cost.
  EXPECT_LT(s.final_cost, start);
}

TEST(LevenbergMarquardt, ARefusedStepLeavesTheStateAndEndsAtTheDampingLimit) {
  // The minimum itself: no step can lower the cost, every trial is refused until lambda passes its maximum.
  CurveFit fit({kA, kB});
  LoopOptions o;
  o.damping = DampingPolicy::multiplicative(1e-4, 0.2, 10.0, 1e-9, 1.0);
  const LoopSummary s = minimize(fit, o);
  EXPECT_EQ(s.steps, 0);
  EXPECT_EQ(s.solves, 5);  // lambda 1e-4 ... 1
  EXPECT_EQ(fit.rejections, 5);
  EXPECT_EQ(fit.x()(0), kA);
  EXPECT_EQ(fit.x()(1), kB);
}

TEST(LevenbergMarquardt, StepLimitEndsWithoutLinearizingAgain) {
  CurveFit fit({1.0, 1.0});
  LoopOptions o;
  o.damping = DampingPolicy::trustRegion(1e4);
  o.max_steps = 2;
  const LoopSummary s = minimize(fit, o);
  EXPECT_EQ(s.steps, 2);
  EXPECT_EQ(fit.linearizations, 2);  // at the start and after the first step
}

}  // namespace
