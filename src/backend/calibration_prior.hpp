#pragma once
// The calibration prior of each refined extrinsic (extrinsic_prior.hpp): its whitened residual and Jacobian,
// the latter at the first estimate when the extrinsic is linked to the marginalization prior.
#include <vector>

#include "mcslam/backend/extrinsic_prior.hpp"
#include "window_term.hpp"

namespace mcslam::backend {

class CalibrationPrior final : public WindowTerm {
 public:
  CalibrationPrior(int num_cameras, const ExtrinsicPriorSigmas& sigmas)
      : sigmas_(sigmas), r_(static_cast<size_t>(num_cameras)), J_(static_cast<size_t>(num_cameras)) {}

  void linearize(const WindowVariables& v) override;
  void addCost(const WindowVariables& v, bool trial, double& cost) const override;
  void addToSystem(const WindowVariables& v, CameraSystem& system) const override;

 private:
  const ExtrinsicPriorSigmas sigmas_;
  std::vector<Vec6> r_;  // per camera (zero without a prior)
  std::vector<Mat6> J_;
};

}  // namespace mcslam::backend
