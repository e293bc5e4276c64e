#include "mcslam/backend/levenberg_marquardt.hpp"

#include <algorithm>

namespace mcslam::backend {

namespace {

// The damping's state between trials: lambda, or the trust radius and the factor it shrinks by next.
struct Damping {
  explicit Damping(const DampingPolicy& p) : policy(p), value(p.initial) {}
  bool trustRegion() const { return policy.kind == DampingPolicy::Kind::TrustRegion; }
  bool exhausted() const { return trustRegion() ? value < policy.min_radius : !(value <= policy.max); }
  double current() const { return trustRegion() ? 1.0 / value : value; }
  void taken(double gain) {
    if (trustRegion()) {
      const double t = 2.0 * gain - 1.0;
      value = std::min(policy.max_radius, value / std::max(1.0 / 3.0, 1.0 - t * t * t));
      shrink = 2.0;
    } else {
      value = std::max(value * policy.accept_factor / policy.accept_divisor, policy.min);
    }
  }
  void refused() {
    if (trustRegion()) {
      value /= shrink;
      shrink *= 2.0;
    } else {
      value *= policy.reject_factor;
    }
  }

  const DampingPolicy& policy;
  double value;
  double shrink = 2.0;
};

}  // namespace

LoopSummary minimize(LeastSquaresProblem& problem, const LoopOptions& options) {
  LoopSummary summary;
  if (!problem.linearize()) {
    summary.failed = true;
    return summary;
  }
  double cost = problem.cost();
  summary.initial_cost = cost;
  Damping damping(options.damping);
  int rejections = 0;
  while (summary.solves < options.max_solves && summary.steps < options.max_steps) {
    if (!damping.trustRegion() && damping.exhausted()) break;
    const double mu = damping.current();
    problem.buildDampedSystem(mu);
    if (problem.maxGradient() <= options.gradient_tolerance) {
      summary.converged = true;
      break;
    }
    ++summary.solves;
    bool small = false;
    if (problem.solveStep()) {
      const double step = problem.stepNorm();
      const double tol = options.parameter_tolerance;
      if (tol >= 0 && step <= tol * (problem.stateNorm() + tol)) {
        summary.converged = true;
        break;
      }
      small = options.small_step != LoopOptions::SmallStep::Ignore && step < options.min_step_norm;
      double predicted = 0, new_cost = 0;
      const bool worth_trying = !damping.trustRegion() || (predicted = problem.modelCostDecrease(mu)) > 0;
      if (worth_trying && problem.evaluateTrial(new_cost)) {
        ++summary.trials;
        const double gain = damping.trustRegion() ? (cost - new_cost) / predicted : 0.0;
        if (damping.trustRegion() ? gain > options.damping.min_gain : new_cost < cost) {
          problem.acceptTrial();
          ++summary.steps;
          rejections = 0;
          damping.taken(gain);
          const double previous = cost;
          if (summary.steps < options.max_steps && !problem.linearize()) {
            summary.failed = true;
            break;
          }
          cost = problem.cost();
          if (options.function_tolerance >= 0 && previous - cost <= options.function_tolerance * previous) {
            summary.converged = true;
            break;
          }
          if (small) {
            summary.converged = true;
            break;
          }
          continue;
        }
      }
    } else if (options.stop_on_failed_solve) {
      break;
    }
    problem.rejectTrial();
    ++rejections;
    damping.refused();
    if (damping.trustRegion() && damping.exhausted()) break;
    if (small && options.small_step == LoopOptions::SmallStep::EndsAfterTrial) {
      summary.converged = true;
      break;
    }
    if (rejections >= options.max_consecutive_rejections) break;
  }
  summary.final_cost = cost;
  return summary;
}

}  // namespace mcslam::backend
