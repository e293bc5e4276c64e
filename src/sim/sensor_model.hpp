#pragma once
// Camera sensor: exposure gain (per camera and drifting over time), vignetting, shot and read noise, gamma
// encoding and 8-bit quantisation. Noise is a pure function of (seed, frame, camera, pixel).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "hash.hpp"
#include "mcslam/sim/renderer.hpp"

namespace mcslam::sim {

class SensorModel {
 public:
  SensorModel(const SensorOptions& options, uint64_t seed);

  // Relative gain of camera `cam` at time t (1 without exposure variation).
  double relativeGain(int cam, double t) const;

  // Linear radiance (already multiplied by the gain) -> grey level, for pixel `index` with noise stream `stream`
  // (one per frame and camera, e.g. from hashOf).
  uint8_t encode(float linear, float vignette, uint32_t stream, uint32_t index) const {
    float v = linear * vignette;
    if (options_.noise) {
      const float sigma = std::sqrt(std::max(0.f, v) * shot_ + read2_);
      v += sigma * gauss_[hash32(stream ^ index) >> (32 - kGaussBits)];
    }
    if (!(v > 0.f)) return 0;
    if (v >= 1.f) return 255;
    return gamma_[static_cast<uint32_t>(v * (kGammaSize - 1) + 0.5f)];
  }
  // Vignetting gain for a bearing whose optical-axis component is bz.
  float vignette(float bz) const {
    if (!options_.vignetting) return 1.f;
    const float s2 = 1.f - bz * bz;  // sin^2 of the angle off the axis (beyond 90 degrees too)
    const float g = 1.f - strength_ * std::min(s2, 1.f);
    return bz < 0.f ? std::max(0.3f, g - strength_ * 0.5f * (-bz)) : std::max(0.3f, g);
  }

 private:
  static constexpr uint32_t kGaussBits = 12;
  static constexpr uint32_t kGaussSize = 1u << kGaussBits;
  static constexpr uint32_t kGammaSize = 65536;
  SensorOptions options_;
  uint64_t seed_;
  float shot_, read2_, strength_;
  std::vector<float> gauss_;
  std::vector<uint8_t> gamma_;
};

}  // namespace mcslam::sim
