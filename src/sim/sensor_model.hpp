#pragma once
// Camera sensor: exposure gain (per camera and drifting over time), vignetting, shot and read noise, gamma
// encoding and 8-bit quantisation. Noise is a pure function of (seed, frame, camera, pixel).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "hash.hpp"
#include "mcslam/sim/renderer.hpp"
#include "simd4.hpp"

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
  // Vignetting gain for a bearing whose optical-axis component is bz (F: float, or f4 for four bearings).
  template <class F>
  F vignette(F bz) const {
    const float s = options_.vignetting ? strength_ : 0.f;  // 0: gain 1 everywhere
    const F g = 1.f - s * vmin(1.f - bz * bz, 1.f);         // 1 - s sin^2 of the angle off the axis (beyond 90 deg too)
    return bz < 0.f ? vmax(g - s * 0.5f * (-bz), 0.3f) : vmax(g, 0.3f);
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
