#pragma once
// The 7-tap Gaussian (sigma 2) of the descriptor's smoothed level, on raw rows. Like orb_fast_kernel.hpp, in an
// anonymous namespace and free of shared inline code: orb_avx2.cpp compiles it for AVX2 (the compiler widens
// the same loops), orb_pyramid.cpp for the baseline; both give identical bytes.
#include <cstdint>

namespace mcslam::orb_detail {
namespace {

// round(256 * exp(-i^2 / 8) / sum) for i = 0..3 (sigma 2), centre adjusted so the taps sum to 256.
constexpr uint16_t kTap0 = 54, kTap1 = 49, kTap2 = 34, kTap3 = 18;
static_assert(kTap0 + 2 * (kTap1 + kTap2 + kTap3) == 256);

inline int clampTo(int v, int lo, int hi) { return v < lo ? lo : (v > hi ? hi : v); }

inline uint8_t blurTaps(int c, int a1, int b1, int a2, int b2, int a3, int b3) {
  const int v = kTap0 * c + kTap1 * (a1 + b1) + kTap2 * (a2 + b2) + kTap3 * (a3 + b3) + 128;
  return static_cast<uint8_t>(v >> 8);
}

// src (w x h) -> dst through tmp (horizontal pass, then vertical); borders clamped.
inline void blur7(const uint8_t* src, int src_stride, uint8_t* dst, int dst_stride, uint8_t* tmp, int tmp_stride, int w,
                  int h) {
  // Horizontal pass into tmp: the interior in 16-bit lanes (the sum fits), the 3-pixel borders clamped.
  for (int y = 0; y < h; ++y) {
    const uint8_t* s = src + static_cast<long>(y) * src_stride;
    uint8_t* t = tmp + static_cast<long>(y) * tmp_stride;
    auto at = [&](int x) { return static_cast<int>(s[clampTo(x, 0, w - 1)]); };
    const int interior_end = w - 3 > 3 ? w - 3 : 3;
    const int left_end = w < 3 ? w : 3;
    for (int x = 0; x < left_end; ++x)
      t[x] = blurTaps(at(x), at(x - 1), at(x + 1), at(x - 2), at(x + 2), at(x - 3), at(x + 3));
    for (int x = 3; x < interior_end; ++x) {
      const uint16_t v = static_cast<uint16_t>(kTap0 * s[x] + kTap1 * static_cast<uint16_t>(s[x - 1] + s[x + 1]) +
                                               kTap2 * static_cast<uint16_t>(s[x - 2] + s[x + 2]) +
                                               kTap3 * static_cast<uint16_t>(s[x - 3] + s[x + 3]) + 128);
      t[x] = static_cast<uint8_t>(v >> 8);
    }
    for (int x = interior_end; x < w; ++x)
      t[x] = blurTaps(at(x), at(x - 1), at(x + 1), at(x - 2), at(x + 2), at(x - 3), at(x + 3));
  }
  // Vertical pass into dst, rows clamped at the borders.
  for (int y = 0; y < h; ++y) {
    const uint8_t* r[7];
    for (int k = 0; k < 7; ++k) r[k] = tmp + static_cast<long>(clampTo(y + k - 3, 0, h - 1)) * tmp_stride;
    uint8_t* d = dst + static_cast<long>(y) * dst_stride;
    for (int x = 0; x < w; ++x) {
      const uint16_t v = static_cast<uint16_t>(kTap0 * r[3][x] + kTap1 * static_cast<uint16_t>(r[2][x] + r[4][x]) +
                                               kTap2 * static_cast<uint16_t>(r[1][x] + r[5][x]) +
                                               kTap3 * static_cast<uint16_t>(r[0][x] + r[6][x]) + 128);
      d[x] = static_cast<uint8_t>(v >> 8);
    }
  }
}

}  // namespace
}  // namespace mcslam::orb_detail
