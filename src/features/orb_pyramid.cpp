#include "orb_pyramid.hpp"

#include <algorithm>
#include <cmath>

namespace mcslam::orb_detail {

void downscale(const ConstPlane& src, const Plane& dst, float ratio, const DownscaleScratch& scratch) {
  const int last_x = src.width - 1, last_y = src.height - 1;
  for (int x = 0; x < dst.width; ++x) {
    const float sx = std::clamp((x + 0.5f) * ratio - 0.5f, 0.0f, static_cast<float>(last_x));
    const int x0 = std::min(static_cast<int>(sx), std::max(last_x - 1, 0));
    scratch.src_x[x] = x0;
    scratch.frac_x[x] = static_cast<uint16_t>(std::lround((sx - x0) * 256.0f));
  }
  uint16_t* row = scratch.row;
  for (int y = 0; y < dst.height; ++y) {
    const float sy = std::clamp((y + 0.5f) * ratio - 0.5f, 0.0f, static_cast<float>(last_y));
    const int y0 = std::min(static_cast<int>(sy), std::max(last_y - 1, 0));
    const uint16_t fy = static_cast<uint16_t>(std::lround((sy - y0) * 256.0f));
    const uint16_t gy = static_cast<uint16_t>(256 - fy);
    const uint8_t* a = src.row(y0);
    const uint8_t* b = src.row(std::min(y0 + 1, last_y));
    for (int x = 0; x < src.width; ++x) row[x] = static_cast<uint16_t>(a[x] * gy + b[x] * fy);  // vectorizes
    row[src.width] = row[src.width - 1];  // a one-column source reads pair[1] here
    uint8_t* out = dst.row(y);
    for (int x = 0; x < dst.width; ++x) {
      const uint16_t* pair = row + scratch.src_x[x];  // src_x <= last_x - 1 (or 0 with one column)
      const uint32_t f = scratch.frac_x[x];
      out[x] = static_cast<uint8_t>((pair[0] * (256u - f) + pair[1] * f + (1u << 15)) >> 16);
    }
  }
}

namespace {

// round(256 * exp(-i^2 / 8) / sum) for i = 0..3 (sigma 2), centre adjusted so the taps sum to 256.
constexpr uint16_t kTap0 = 54, kTap1 = 49, kTap2 = 34, kTap3 = 18;
static_assert(kTap0 + 2 * (kTap1 + kTap2 + kTap3) == 256);

inline uint8_t blurTaps(int c, int a1, int b1, int a2, int b2, int a3, int b3) {
  const int v = kTap0 * c + kTap1 * (a1 + b1) + kTap2 * (a2 + b2) + kTap3 * (a3 + b3) + 128;
  return static_cast<uint8_t>(v >> 8);
}

}  // namespace

void gaussianBlur7(const ConstPlane& src, const Plane& dst, const Plane& tmp) {
  const int w = src.width, h = src.height;
  // Horizontal pass into tmp: the interior in 16-bit lanes (the sum fits), the 3-pixel borders clamped.
  for (int y = 0; y < h; ++y) {
    const uint8_t* s = src.row(y);
    uint8_t* t = tmp.row(y);
    auto at = [&](int x) { return static_cast<int>(s[std::clamp(x, 0, w - 1)]); };
    const int interior_end = std::max(w - 3, 3);
    for (int x = 0; x < std::min(3, w); ++x)
      t[x] = blurTaps(at(x), at(x - 1), at(x + 1), at(x - 2), at(x + 2), at(x - 3), at(x + 3));
    for (int x = 3; x < interior_end; ++x) {
      const uint16_t v = static_cast<uint16_t>(
          kTap0 * s[x] + kTap1 * static_cast<uint16_t>(s[x - 1] + s[x + 1]) +
          kTap2 * static_cast<uint16_t>(s[x - 2] + s[x + 2]) + kTap3 * static_cast<uint16_t>(s[x - 3] + s[x + 3]) + 128);
      t[x] = static_cast<uint8_t>(v >> 8);
    }
    for (int x = std::max(interior_end, 3); x < w; ++x)
      t[x] = blurTaps(at(x), at(x - 1), at(x + 1), at(x - 2), at(x + 2), at(x - 3), at(x + 3));
  }
  // Vertical pass into dst, rows clamped at the borders.
  for (int y = 0; y < h; ++y) {
    const uint8_t* r[7];
    for (int k = 0; k < 7; ++k) r[k] = tmp.row(std::clamp(y + k - 3, 0, h - 1));
    uint8_t* d = dst.row(y);
    for (int x = 0; x < w; ++x) {
      const uint16_t v = static_cast<uint16_t>(
          kTap0 * r[3][x] + kTap1 * static_cast<uint16_t>(r[2][x] + r[4][x]) +
          kTap2 * static_cast<uint16_t>(r[1][x] + r[5][x]) + kTap3 * static_cast<uint16_t>(r[0][x] + r[6][x]) + 128);
      d[x] = static_cast<uint8_t>(v >> 8);
    }
  }
}

}  // namespace mcslam::orb_detail
