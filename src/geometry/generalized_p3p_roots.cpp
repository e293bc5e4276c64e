#include "mcslam/geometry/generalized_p3p_roots.hpp"

#include <algorithm>
#include <cmath>

namespace mcslam {

namespace {

// |p(x)| below this fraction of sum |a_i x^i| is zero at double precision (with margin for the
// rounding already in the coefficients).
constexpr double kRelativeZero = 1e-10;
// Roots are bracketed to this relative width: Newton converges quadratically well before, and
// callers that need more polish the root on their own equations (the P3P does).
constexpr double kRootTolerance = 1e-11;

// Sum of |a_i| |x|^i: the scale against which p(x) is compared with zero.
double magnitudeScale(const double* a, int n, double x) {
  const double ax = std::abs(x);
  double s = 0;
  for (int i = n; i >= 0; --i) s = s * ax + std::abs(a[i]);
  return s;
}

void evaluateWithDerivative(const double* a, int n, double x, double& p, double& dp) {
  p = a[n];
  dp = 0;
  for (int i = n - 1; i >= 0; --i) {
    dp = dp * x + p;
    p = p * x + a[i];
  }
}

// p is monotonic on [lo, hi] and p(lo), p(hi) have opposite signs: Newton kept inside the bracket.
double rootInBracket(const double* a, int n, double lo, double hi, double p_lo) {
  double x = 0.5 * (lo + hi);
  double step_before = hi - lo;
  for (int it = 0; it < 200; ++it) {
    double p, dp;
    evaluateWithDerivative(a, n, x, p, dp);
    if (p == 0) return x;
    if ((p < 0) == (p_lo < 0)) {
      lo = x;
    } else {
      hi = x;
    }
    double next = (dp != 0) ? x - p / dp : lo - 1;
    // Bisect when Newton jumps out of the bracket or does not at least halve the step.
    if (!(next > lo && next < hi) || std::abs(next - x) > 0.5 * step_before) next = 0.5 * (lo + hi);
    step_before = std::abs(next - x);
    x = next;
    if (hi - lo <= kRootTolerance * std::max(1.0, std::abs(x)) ||
        step_before <= 0.01 * kRootTolerance * std::max(1.0, std::abs(x)))
      break;
  }
  return x;
}

// A (near) double root can be found twice, at a critical point and at a rounding-level sign change
// beside it (they differ by about the square root of the rounding): keep one.
void appendRoot(double x, double* roots, int& count) {
  if (count > 0 && std::abs(x - roots[count - 1]) <= 1e-7 * std::max(1.0, std::abs(x))) return;
  roots[count++] = x;
}

int rootsOfTrimmed(const double* a, int n, double lo, double hi, double* roots) {
  if (n <= 0) return 0;
  int count = 0;
  if (n == 1) {
    const double x = -a[0] / a[1];
    if (x >= lo && x <= hi) roots[count++] = x;
    return count;
  }
  // Critical points split [lo, hi] into monotonic pieces.
  double deriv[kMaxPolynomialDegree];
  for (int i = 1; i <= n; ++i) deriv[i - 1] = i * a[i];
  double critical[kMaxPolynomialDegree];
  const int num_critical = rootsOfTrimmed(deriv, n - 1, lo, hi, critical);

  double left = lo;
  double p_left = evaluatePolynomial(a, n, left);
  if (p_left == 0) appendRoot(left, roots, count);
  for (int k = 0; k <= num_critical; ++k) {
    const double right = (k < num_critical) ? critical[k] : hi;
    if (right <= left) continue;
    const double p_right = evaluatePolynomial(a, n, right);
    if (p_left != 0 && p_right != 0 && ((p_left < 0) != (p_right < 0))) {
      appendRoot(rootInBracket(a, n, left, right, p_left), roots, count);
    }
    const bool touches = (k < num_critical) && std::abs(p_right) <= kRelativeZero * magnitudeScale(a, n, right);
    if (p_right == 0 || touches) appendRoot(right, roots, count);
    left = right;
    p_left = p_right;
  }
  return count;
}

}  // namespace

double evaluatePolynomial(const double* a, int n, double x) {
  double p = a[n];
  for (int i = n - 1; i >= 0; --i) p = p * x + a[i];
  return p;
}

int realPolynomialRoots(const double* coeffs, int degree, double lo, double hi, double* roots) {
  int n = std::min(degree, kMaxPolynomialDegree);
  while (n > 0 && coeffs[n] == 0) --n;
  if (n == 0 || !(lo <= hi)) return 0;
  // Fujiwara's bound on the magnitude of every (complex) root; by Gauss-Lucas it holds for the
  // roots of the derivatives too, so the whole recursion searches no wider than needed.
  double bound = 0;
  for (int k = 1; k <= n; ++k) {
    const double ratio = std::abs(coeffs[n - k] / coeffs[n]) / (k == n ? 2.0 : 1.0);
    bound = std::max(bound, std::pow(ratio, 1.0 / k));
  }
  bound *= 2.0;
  if (std::isfinite(bound)) {
    lo = std::max(lo, -bound);
    hi = std::min(hi, bound);
    if (!(lo <= hi)) return 0;
  }
  return rootsOfTrimmed(coeffs, n, lo, hi, roots);
}

}  // namespace mcslam
