// The ORB kernels built for AVX2: FAST-9 on 32 pixels at a time and the 7-tap blur (the compiler widens its
// loops). This file alone is compiled with -mavx2 (src/features/CMakeLists.txt) and runs only where the CPU
// reports AVX2 (fastHasWideSimd()): the types and kernels live in anonymous namespaces and use no shared inline
// code, so no AVX2 instruction can stand in for a baseline function at link time (`nm` on the object lists
// only the two entry points below as defined symbols).
#include "orb_fast.hpp"

#if defined(MCSLAM_ORB_HAVE_AVX2_UNIT)
#include <immintrin.h>

#include "orb_blur_kernel.hpp"
#include "orb_fast_kernel.hpp"

namespace mcslam::orb_detail {
namespace {

struct U8x32 {
  static constexpr int kLanes = 32;
  __m256i v;

  static U8x32 load(const uint8_t* p) { return {_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p))}; }
  static U8x32 splat(uint8_t x) { return {_mm256_set1_epi8(static_cast<char>(x))}; }
  void store(uint8_t* p) const { _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), v); }
  bool anyNonZero() const { return !_mm256_testz_si256(v, v); }
  friend U8x32 min(U8x32 a, U8x32 b) { return {_mm256_min_epu8(a.v, b.v)}; }
  friend U8x32 max(U8x32 a, U8x32 b) { return {_mm256_max_epu8(a.v, b.v)}; }
  friend U8x32 subs(U8x32 a, U8x32 b) { return {_mm256_subs_epu8(a.v, b.v)}; }
  friend U8x32 adds(U8x32 a, U8x32 b) { return {_mm256_adds_epu8(a.v, b.v)}; }
  friend U8x32 keepAbove(U8x32 a, U8x32 t) {
    const __m256i not_above = _mm256_cmpeq_epi8(_mm256_subs_epu8(a.v, t.v), _mm256_setzero_si256());
    return {_mm256_andnot_si256(not_above, a.v)};
  }
};

}  // namespace

int fastScoreRowAvx2(const uint8_t* image, int stride, int y, int x0, int x1, int threshold, uint8_t* out) {
  return scoreRow<U8x32>(image, stride, y, x0, x1, threshold, out);
}

void gaussianBlur7Avx2(const uint8_t* src, int src_stride, uint8_t* dst, int dst_stride, uint8_t* tmp, int tmp_stride,
                       int w, int h) {
  blur7(src, src_stride, dst, dst_stride, tmp, tmp_stride, w, h);
}

}  // namespace mcslam::orb_detail
#endif
