#pragma once
// One bilinear sample of an 8-bit image at (x, y), both >= 0 with (x + 1, y + 1) inside: the operations every
// sampler of the epipolar alignment repeats (its vector kernels compute the same lanes in the same order).
#include <cstddef>
#include <cstdint>

#include "mcslam/core/image.hpp"

namespace mcslam {

inline float sampleBilinear(const ImageView& im, float x, float y) {
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);  // positions are >= 0: truncation floors
  const float ax = x - static_cast<float>(x0), ay = y - static_cast<float>(y0);
  const uint8_t* p = im.data + static_cast<std::ptrdiff_t>(y0) * im.stride + x0;
  const float p00 = p[0], p10 = p[1], p01 = p[im.stride], p11 = p[im.stride + 1];
  const float top = p00 + ax * (p10 - p00), bottom = p01 + ax * (p11 - p01);
  return top + ay * (bottom - top);
}

}  // namespace mcslam
