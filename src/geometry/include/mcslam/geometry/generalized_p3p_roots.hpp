#pragma once
// Real roots of a small univariate polynomial in an interval, for the generalized P3P's octic.
// Allocation-free: fixed-size arrays on the stack, no eigen-decomposition.
//
// Method: the roots of p' split the interval into pieces where p is monotonic (recursively, down
// to a linear polynomial), so each piece holds at most one root, found by Newton's method kept
// inside its bracket (bisection when Newton leaves it). Unlike a companion matrix this never has
// to decide whether a complex eigenvalue is "real enough"; unlike a Sturm sequence it has no
// coefficient growth. A critical point where |p| is at rounding level is a (near) double root and
// is reported too, so tangent solutions are not lost.

namespace mcslam {

inline constexpr int kMaxPolynomialDegree = 8;

// p(x) = coeffs[0] + coeffs[1] x + ... + coeffs[degree] x^degree, degree <= kMaxPolynomialDegree.
double evaluatePolynomial(const double* coeffs, int degree, double x);

// Writes the real roots of p in [lo, hi] to roots (ascending, at most `degree` of them) and returns
// their count. Leading zero coefficients are dropped; a polynomial that is identically zero has no
// roots reported.
int realPolynomialRoots(const double* coeffs, int degree, double lo, double hi, double* roots);

}  // namespace mcslam
