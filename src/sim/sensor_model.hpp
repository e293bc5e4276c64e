#pragma once
// Camera sensor: exposure gain (per camera and drifting over time), vignetting, shot and read noise, gamma
// encoding and 8-bit quantisation. Noise is a pure function of (seed, frame, camera, pixel).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "hash.hpp"
#include "simd4.hpp"
#include "mcslam/sim/renderer.hpp"

namespace mcslam::sim {

class SensorModel {
 public:
  SensorModel(const SensorOptions& options, uint64_t seed);

  // Relative gain of camera `cam` at time t (1 without exposure variation).
  double relativeGain(int cam, double t) const;

  // Linear radiance (already multiplied by the gain) of four pixels -> grey levels, for pixels index, index + 1,
  // ... with noise stream `stream` (one per frame and camera, e.g. from hashOf). Pixels with vignette 0 (outside
  // the lens's domain) are black. Branch-free: saturated lights and black borders cost no mispredictions.
  void encode4(f4 linear, f4 vignette, uint32_t stream, uint32_t index, uint8_t out[4]) const {
    f4 v = linear * vignette;
    if (options_.noise) {
      const f4 sigma2 = vmax(v, 0.f) * shot_ + read2_;
      const u4 h = hash32(u4{index, index + 1, index + 2, index + 3} ^ stream) >> (32 - kGaussBits);
      v += lanes([&](int l) { return std::sqrt(sigma2[l]) * gauss_[h[l]]; });
    }
    v = vignette > 0.f ? vmin(vmax(v, 0.f), 1.f) : splat(0.f);  // NaN -> 0 too
    const i4 level = toInt(v * static_cast<float>(kGammaSize - 1) + 0.5f);
    for (int l = 0; l < 4; ++l) out[l] = gamma_[level[l]];
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
