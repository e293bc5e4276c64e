#pragma once
// The damped least-squares loop (Levenberg-Marquardt) of every optimizer of the SLAM core: the sliding-window
// solver, the scale estimator, pose refinement and relative-pose refinement.
//
// The loop owns the schedule: when to linearize, the damping and how it moves, which trial step is taken, when
// to stop. The problem owns the arithmetic: its state, its normal equations (dense, or reduced by a Schur
// complement), the damped solve and the cost at a trial step. The problem is called a handful of times per
// trial, never per residual: a virtual interface costs nothing measurable here, and keeps one compiled loop.
// Allocates nothing.
#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>

namespace mcslam::backend {

// How the damping moves. The problem receives it as one number: lambda (Marquardt) or mu = 1 / radius (trust
// region), and adds it times its diagonal scaling (dampedMatrix) to the normal equations. Every optimizer of the
// core uses the trust region; Marquardt's multiplicative lambda stays as a kind for comparison
// (docs/design/optim.md).
struct DampingPolicy {
  enum class Kind {
    // Marquardt's lambda: a trial is taken when it lowers the cost; lambda then becomes
    // max(lambda * accept_factor / accept_divisor, min), and after a refused trial lambda * reject_factor.
    Multiplicative,
    // Trust region (the form Ceres's LEVENBERG_MARQUARDT uses): mu = 1 / radius; a trial is taken when the cost
    // fell by more than min_gain of the decrease the model predicted; the radius grows with that gain ratio and
    // shrinks by a factor that doubles with each refusal in a row.
    TrustRegion,
  };
  Kind kind = Kind::TrustRegion;
  double initial = 1e4;  // lambda, or the radius
  // Multiplicative.
  double accept_factor = 0.2;
  double accept_divisor = 1.0;
  double reject_factor = 10.0;
  double min = 1e-9;                                     // lambda after a taken step stays above
  double max = std::numeric_limits<double>::infinity();  // no trial with lambda above: the loop stops
  // Trust region.
  double min_gain = 1e-3;
  double min_radius = 1e-32, max_radius = 1e16;

  static DampingPolicy trustRegion(double initial_radius) {
    DampingPolicy p;
    p.kind = Kind::TrustRegion;
    p.initial = initial_radius;
    return p;
  }
  static DampingPolicy multiplicative(double initial, double accept_factor, double reject_factor, double min,
                                      double max) {
    DampingPolicy p;
    p.kind = Kind::Multiplicative;
    p.initial = initial;
    p.accept_factor = accept_factor;
    p.reject_factor = reject_factor;
    p.min = min;
    p.max = max;
    return p;
  }
};

// What ends the loop besides the damping policy's own limit. A negative tolerance is off.
struct LoopOptions {
  DampingPolicy damping;
  int max_solves = INT_MAX;  // linear solves (trial steps), taken or not
  int max_steps = INT_MAX;   // taken steps; the loop stops right after the last one without linearizing again
  int max_consecutive_rejections = INT_MAX;
  double gradient_tolerance = -1;   // before a solve: max |gradient| <= this: converged
  double parameter_tolerance = -1;  // after a solve: |dx| <= tol * (|x| + tol): converged, the step not tried
  double function_tolerance = -1;   // after a taken step: (old - new) cost <= tol * old: converged
  // Small steps: |dx| < min_step_norm ends the loop after the trial (taken or not), or only once taken.
  enum class SmallStep { Ignore, EndsAfterTrial, EndsOnceTaken };
  SmallStep small_step = SmallStep::Ignore;
  double min_step_norm = 0;
  bool stop_on_failed_solve = false;  // else a failed solve counts as a refused trial
};

struct LoopSummary {
  int solves = 0;  // linear solves
  int trials = 0;  // trial steps whose cost was evaluated
  int steps = 0;   // taken
  double initial_cost = 0, final_cost = 0;
  bool converged = false;  // a tolerance was met
  bool failed = false;     // the problem could not be linearized
};

// The problem the loop drives. Its state is the current point; evaluateTrial() looks at state (+) step without
// changing it, acceptTrial() moves it there.
class LeastSquaresProblem {
 public:
  virtual ~LeastSquaresProblem() = default;
  // Normal equations at the current state; false when they cannot be formed (not finite): the loop fails.
  virtual bool linearize() = 0;
  virtual double cost() const = 0;  // at the current state (after linearize(), or the taken trial's)
  // Forms the damped system for `damping` (lambda or mu, see DampingPolicy).
  virtual void buildDampedSystem(double damping) = 0;
  virtual double maxGradient() const { return std::numeric_limits<double>::infinity(); }
  virtual bool solveStep() = 0;  // false: no finite step
  virtual double stepNorm() const = 0;
  virtual double stateNorm() const { return 0; }
  // Decrease of the cost's quadratic model along the step (trust region only).
  virtual double modelCostDecrease(double damping) const = 0;
  // Cost at state (+) step; false when the step leaves the problem's domain.
  virtual bool evaluateTrial(double& cost) = 0;
  virtual void acceptTrial() = 0;
  virtual void rejectTrial() {}
};

LoopSummary minimize(LeastSquaresProblem& problem, const LoopOptions& options);

// Marquardt's scaling of the damping (the window solver's, and Ceres's): mu times the diagonal of H, clamped so
// that a variable without information still gets a (tiny) positive pivot and a huge one no infinite damping.
constexpr double kMinDampingDiagonal = 1e-6, kMaxDampingDiagonal = 1e32;
inline double dampingDiagonal(double h) { return std::clamp(h, kMinDampingDiagonal, kMaxDampingDiagonal); }

// A = H + mu * D for a dense H (D: dampingDiagonal of H's diagonal).
template <class Matrix>
void dampedMatrix(const Matrix& H, double mu, Matrix& A) {
  A = H;
  for (int i = 0; i < static_cast<int>(H.rows()); ++i) A(i, i) += mu * dampingDiagonal(H(i, i));
}

}  // namespace mcslam::backend
