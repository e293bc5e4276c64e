#include "sensor_model.hpp"

#include <algorithm>
#include <cmath>

namespace mcslam::sim {

namespace {

// Inverse of the standard normal CDF (Acklam's rational approximation, |error| < 1.2e-9).
double inverseNormal(double p) {
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,  -2.759285104469687e+02,
                             1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                             6.680131188771972e+01, -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                             -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                             3.754408661907416e+00};
  const double lo = 0.02425;
  if (p < lo) {
    const double q = std::sqrt(-2 * std::log(p));
    return (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
           ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  }
  if (p > 1 - lo) return -inverseNormal(1 - p);
  const double q = p - 0.5, r = q * q;
  return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
         (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
}

}  // namespace

SensorModel::SensorModel(const SensorOptions& options, uint64_t seed) : options_(options), seed_(seed) {
  shot_ = static_cast<float>(std::max(0.0, options.shot_noise));
  read2_ = static_cast<float>(options.read_noise * options.read_noise);
  strength_ = static_cast<float>(std::clamp(options.vignetting_strength, 0.0, 0.7));
  gauss_.resize(kGaussSize);
  for (uint32_t i = 0; i < kGaussSize; ++i) gauss_[i] = static_cast<float>(inverseNormal((i + 0.5) / kGaussSize));
  gamma_.resize(kGammaSize);
  const double inv_gamma = 1.0 / std::max(0.1, options.gamma);
  for (uint32_t i = 0; i < kGammaSize; ++i) {
    gamma_[i] = static_cast<uint8_t>(std::lround(255.0 * std::pow(i / double(kGammaSize - 1), inv_gamma)));
  }
}

double SensorModel::relativeGain(int cam, double t) const {
  if (!options_.exposure_variation) return 1.0;
  // A fixed offset per camera and a slow drift: mostly common to all cameras (auto exposure reacting to the
  // same scene), partly per camera.
  const double offset = 0.10 * (2 * unitFromHash(hashOf(seed_, 0xca3, static_cast<uint64_t>(cam))) - 1);
  static const double kPeriods[] = {9.0, 23.0, 51.0};
  static const double kWeights[] = {0.35, 0.4, 0.25};
  double common = 0, own = 0;
  for (int k = 0; k < 3; ++k) {
    const double pc = 2 * M_PI * unitFromHash(hashOf(seed_, 0xd1f, k));
    const double po = 2 * M_PI * unitFromHash(hashOf(seed_, 0xd2f, static_cast<uint64_t>(cam), k));
    common += kWeights[k] * std::sin(2 * M_PI * t / kPeriods[k] + pc);
    own += kWeights[k] * std::sin(2 * M_PI * t / (0.8 * kPeriods[k]) + po);
  }
  return std::exp(offset + 0.12 * common + 0.04 * own);
}

}  // namespace mcslam::sim
