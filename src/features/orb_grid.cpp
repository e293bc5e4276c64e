#include "orb_grid.hpp"

#include <algorithm>
#include <cstring>

#include "orb_simd.hpp"

namespace mcslam::orb_detail {

namespace {

void collectScalar(const ConstPlane& scores, const Rect& rect, std::vector<Corner>& out) {
  const int stride = scores.stride;
  for (int y = rect.y0; y < rect.y1; ++y) {
    const uint8_t* row = scores.row(y);
    for (int x = rect.x0; x < rect.x1; x += 16) {
      // Most of the map is zero: skip 16 pixels at a time (reading past rect.x1 stays inside the
      // padded plane; only the lanes inside the rect are looked at).
      const int n = std::min(16, rect.x1 - x);
      uint64_t words[2];
      std::memcpy(words, row + x, sizeof words);
      if ((words[0] | words[1]) == 0) continue;
      for (int i = 0; i < n; ++i) {
        const uint8_t* p = row + x + i;
        const int s = *p;
        if (s == 0) continue;
        const bool is_max = s >= p[-stride - 1] && s >= p[-stride] && s >= p[-stride + 1] && s >= p[-1] && s > p[1] &&
                            s > p[stride - 1] && s > p[stride] && s > p[stride + 1];
        if (is_max && out.size() < out.capacity()) out.push_back({x + i, y, static_cast<float>(s)});
      }
    }
  }
}

#if defined(MCSLAM_ORB_HAVE_SSE2)
// The same test on 16 pixels at once: not below the four neighbours before it in raster order
// (max(s, before) == s) and above the four after it (saturated s - after != 0); the set bits in order.
void collectSse2(const ConstPlane& scores, const Rect& rect, std::vector<Corner>& out) {
  const int stride = scores.stride;
  const __m128i zero = _mm_setzero_si128();
  auto load = [](const uint8_t* p) { return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p)); };
  for (int y = rect.y0; y < rect.y1; ++y) {
    const uint8_t* row = scores.row(y);
    const uint8_t* up = row - stride;
    const uint8_t* down = row + stride;
    for (int x = rect.x0; x < rect.x1; x += 16) {
      const int n = std::min(16, rect.x1 - x);
      const __m128i s = load(row + x);
      const int lanes = n == 16 ? 0xFFFF : (1 << n) - 1;
      const int live = ~_mm_movemask_epi8(_mm_cmpeq_epi8(s, zero)) & lanes;
      if (live == 0) continue;
      const __m128i before =
          _mm_max_epu8(_mm_max_epu8(load(up + x - 1), load(up + x)), _mm_max_epu8(load(up + x + 1), load(row + x - 1)));
      const __m128i after = _mm_max_epu8(_mm_max_epu8(load(down + x - 1), load(down + x)),
                                         _mm_max_epu8(load(down + x + 1), load(row + x + 1)));
      const int not_below = _mm_movemask_epi8(_mm_cmpeq_epi8(_mm_max_epu8(s, before), s));
      const int above = ~_mm_movemask_epi8(_mm_cmpeq_epi8(_mm_subs_epu8(s, after), zero));
      for (unsigned mask = static_cast<unsigned>(live & not_below & above); mask != 0; mask &= mask - 1) {
        const int i = __builtin_ctz(mask);
        if (out.size() < out.capacity()) out.push_back({x + i, y, static_cast<float>(row[x + i])});
      }
    }
  }
}
#elif defined(MCSLAM_ORB_HAVE_NEON)
// The SSE2 kernel's test with NEON: each lane's comparison as one bit of a 16-bit mask (lane i is bit i).
inline unsigned laneMask(uint8x16_t v) {
  static const uint8_t kBits[16] = {1, 2, 4, 8, 16, 32, 64, 128, 1, 2, 4, 8, 16, 32, 64, 128};
  const uint8x16_t bits = vandq_u8(v, vld1q_u8(kBits));
  return vaddv_u8(vget_low_u8(bits)) | (static_cast<unsigned>(vaddv_u8(vget_high_u8(bits))) << 8);
}

void collectNeon(const ConstPlane& scores, const Rect& rect, std::vector<Corner>& out) {
  const int stride = scores.stride;
  for (int y = rect.y0; y < rect.y1; ++y) {
    const uint8_t* row = scores.row(y);
    const uint8_t* up = row - stride;
    const uint8_t* down = row + stride;
    for (int x = rect.x0; x < rect.x1; x += 16) {
      const int n = std::min(16, rect.x1 - x);
      const uint8x16_t s = vld1q_u8(row + x);
      if (vmaxvq_u8(s) == 0) continue;
      const unsigned lanes = n == 16 ? 0xFFFFu : (1u << n) - 1;
      const uint8x16_t before = vmaxq_u8(vmaxq_u8(vld1q_u8(up + x - 1), vld1q_u8(up + x)),
                                         vmaxq_u8(vld1q_u8(up + x + 1), vld1q_u8(row + x - 1)));
      const uint8x16_t after = vmaxq_u8(vmaxq_u8(vld1q_u8(down + x - 1), vld1q_u8(down + x)),
                                        vmaxq_u8(vld1q_u8(down + x + 1), vld1q_u8(row + x + 1)));
      // s non-zero, s >= every neighbour before it, s > every neighbour after it.
      const uint8x16_t keep = vandq_u8(vtstq_u8(s, s), vandq_u8(vcgeq_u8(s, before), vcgtq_u8(s, after)));
      for (unsigned mask = laneMask(keep) & lanes; mask != 0; mask &= mask - 1) {
        const int i = __builtin_ctz(mask);
        if (out.size() < out.capacity()) out.push_back({x + i, y, static_cast<float>(row[x + i])});
      }
    }
  }
}
#endif

}  // namespace

void collectLocalMaxima(const ConstPlane& scores, const Rect& rect, std::vector<Corner>& out, bool use_simd) {
#if defined(MCSLAM_ORB_HAVE_SSE2)
  if (use_simd) return collectSse2(scores, rect, out);
#elif defined(MCSLAM_ORB_HAVE_NEON)
  if (use_simd) return collectNeon(scores, rect, out);
#else
  (void)use_simd;
#endif
  collectScalar(scores, rect, out);
}

Grid::Grid(const Rect& r, int cell_size) : region(r), cell(std::max(cell_size, 1)) {
  cols = r.empty() ? 0 : (r.x1 - r.x0 + cell - 1) / cell;
  rows = r.empty() ? 0 : (r.y1 - r.y0 + cell - 1) / cell;
}

Rect Grid::cellRect(int index) const {
  const int cx = index % cols, cy = index / cols;
  const int x0 = region.x0 + cx * cell, y0 = region.y0 + cy * cell;
  return {x0, y0, std::min(x0 + cell, region.x1), std::min(y0 + cell, region.y1)};
}

}  // namespace mcslam::orb_detail
