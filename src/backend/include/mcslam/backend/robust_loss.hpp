#pragma once
// Robust losses on the squared whitened residual s = |r|^2, r = (predicted - measured) / sigma.
// Cost of one residual is 0.5 * rho(s), the same convention as Ceres (HuberLoss, CauchyLoss), so
// both solvers minimise the same function.
#include <cmath>

namespace mcslam::backend {

enum class LossKind { Trivial, Huber, Cauchy };

struct RobustLoss {
  LossKind kind = LossKind::Huber;
  // Threshold on |r|, in units of sigma: a pixel threshold at octave 0, scaled by 1.2^octave.
  double threshold = 2.447;  // sqrt(5.991), the 95% chi-square bound of 2 dof

  // rho(s) and its derivative rho'(s), the IRLS weight of the residual.
  void evaluate(double s, double& rho, double& weight) const {
    const double a2 = threshold * threshold;
    rho = s;
    weight = 1.0;
    switch (kind) {
      case LossKind::Trivial: return;
      case LossKind::Huber:
        if (s <= a2) {
          rho = s;
          weight = 1.0;
        } else {
          const double r = std::sqrt(s);
          rho = 2.0 * threshold * r - a2;
          weight = threshold / r;
        }
        return;
      case LossKind::Cauchy:
        rho = a2 * std::log1p(s / a2);
        weight = 1.0 / (1.0 + s / a2);
        return;
    }
  }
  double rho(double s) const {
    double r, w;
    evaluate(s, r, w);
    return r;
  }
};

}  // namespace mcslam::backend
