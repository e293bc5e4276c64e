#include "orb_pyramid.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "orb_blur_kernel.hpp"
#include "orb_fast.hpp"
#include "orb_simd.hpp"

namespace mcslam::orb_detail {

namespace {

// The vertical pass keeps 6 fractional bits (values < 2^14, so pairs fit signed 16-bit multiplies),
// the horizontal one 8: the result drops 14.
constexpr int kShift = 14;
constexpr uint32_t kRound = 1u << (kShift - 1);

// Weighted sum of each source pair row[x0], row[x0 + 1] (both in one 32-bit load), weights (256 - f, f).
inline uint8_t resamplePair(const int16_t* row, int32_t x0, uint32_t weights) {
  uint32_t pair;
  std::memcpy(&pair, row + x0, sizeof pair);
  const uint32_t v = (pair & 0xFFFFu) * (weights & 0xFFFFu) + (pair >> 16) * (weights >> 16);
  return static_cast<uint8_t>((v + kRound) >> kShift);
}

void resampleRow(const int16_t* row, const DownscaleScratch& scratch, int width, uint8_t* out, bool use_simd) {
  int x = 0;
#if defined(MCSLAM_ORB_HAVE_SSE2)
  // Four pairs per register; madd multiplies and adds each pair with its weights exactly as above.
  auto gather4 = [&](int i) {
    uint32_t p[4];
    for (int k = 0; k < 4; ++k) std::memcpy(&p[k], row + scratch.src_x[i + k], sizeof(uint32_t));
    return _mm_set_epi32(static_cast<int>(p[3]), static_cast<int>(p[2]), static_cast<int>(p[1]),
                         static_cast<int>(p[0]));
  };
  const __m128i round = _mm_set1_epi32(static_cast<int>(kRound));
  for (; use_simd && x + 8 <= width; x += 8) {
    const __m128i w0 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(scratch.weights + x));
    const __m128i w1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(scratch.weights + x + 4));
    const __m128i s0 = _mm_srli_epi32(_mm_add_epi32(_mm_madd_epi16(gather4(x), w0), round), kShift);
    const __m128i s1 = _mm_srli_epi32(_mm_add_epi32(_mm_madd_epi16(gather4(x + 4), w1), round), kShift);
    const __m128i bytes = _mm_packus_epi16(_mm_packs_epi32(s0, s1), _mm_setzero_si128());
    _mm_storel_epi64(reinterpret_cast<__m128i*>(out + x), bytes);
  }
#elif defined(MCSLAM_ORB_HAVE_NEON)
  // Four pairs per register as 32-bit words: low * left weight + high * right weight, as above (exact integers).
  auto gather4 = [&](int i) {
    uint32_t p[4];
    for (int k = 0; k < 4; ++k) std::memcpy(&p[k], row + scratch.src_x[i + k], sizeof(uint32_t));
    return vld1q_u32(p);
  };
  const uint32x4_t low16 = vdupq_n_u32(0xFFFFu);
  auto weigh4 = [&](int i) {
    const uint32x4_t pairs = gather4(i), w = vld1q_u32(scratch.weights + i);
    const uint32x4_t sum =
        vmlaq_u32(vmulq_u32(vandq_u32(pairs, low16), vandq_u32(w, low16)), vshrq_n_u32(pairs, 16), vshrq_n_u32(w, 16));
    return vqmovn_u32(vshrq_n_u32(vaddq_u32(sum, vdupq_n_u32(kRound)), kShift));
  };
  for (; use_simd && x + 8 <= width; x += 8) vst1_u8(out + x, vqmovn_u16(vcombine_u16(weigh4(x), weigh4(x + 4))));
#else
  (void)use_simd;
#endif
  for (; x < width; ++x) out[x] = resamplePair(row, scratch.src_x[x], scratch.weights[x]);
}

}  // namespace

void downscale(const ConstPlane& src, const Plane& dst, float ratio, const DownscaleScratch& scratch, bool use_simd) {
  const int last_x = src.width - 1, last_y = src.height - 1;
  for (int x = 0; x < dst.width; ++x) {
    const float sx = std::clamp((static_cast<float>(x) + 0.5f) * ratio - 0.5f, 0.0f, static_cast<float>(last_x));
    const int x0 = std::min(static_cast<int>(sx), std::max(last_x - 1, 0));
    const uint32_t f = static_cast<uint32_t>(std::lround((sx - static_cast<float>(x0)) * 256.0f));
    scratch.src_x[x] = x0;
    scratch.weights[x] = (256u - f) | (f << 16);
  }
  int16_t* row = scratch.row;
  for (int y = 0; y < dst.height; ++y) {
    const float sy = std::clamp((static_cast<float>(y) + 0.5f) * ratio - 0.5f, 0.0f, static_cast<float>(last_y));
    const int y0 = std::min(static_cast<int>(sy), std::max(last_y - 1, 0));
    const uint16_t fy = static_cast<uint16_t>(std::lround((sy - static_cast<float>(y0)) * 256.0f));
    const uint16_t gy = static_cast<uint16_t>(256 - fy);
    const uint8_t* a = src.row(y0);
    const uint8_t* b = src.row(std::min(y0 + 1, last_y));
    // Vertical first (contiguous, vectorizes), 6 fractional bits kept.
    for (int x = 0; x < src.width; ++x)
      row[x] = static_cast<int16_t>(static_cast<uint16_t>(a[x] * gy + b[x] * fy + 2) >> 2);
    row[src.width] = row[src.width - 1];  // a one-column source reads its pair's second value here
    resampleRow(row, scratch, dst.width, dst.row(y), use_simd);
  }
}

void gaussianBlur7(const ConstPlane& src, const Plane& dst, const Plane& tmp, bool use_simd) {
#if defined(MCSLAM_ORB_HAVE_AVX2_UNIT)
  if (use_simd && fastHasWideSimd()) {
    return gaussianBlur7Avx2(src.data, src.stride, dst.data, dst.stride, tmp.data, tmp.stride, src.width, src.height);
  }
#endif
  (void)use_simd;
  blur7(src.data, src.stride, dst.data, dst.stride, tmp.data, tmp.stride, src.width, src.height);
}

}  // namespace mcslam::orb_detail
