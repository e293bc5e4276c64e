#pragma once
// 16 x uint8 vectors for the FAST kernel: SSE2 (baseline on x86-64), NEON (baseline on AArch64) and a
// portable scalar reference. The kernel is a template over these types, so the scalar path is compiled
// and tested on every machine, and the native one must give identical results.
#include <algorithm>
#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#define MCSLAM_ORB_HAVE_SSE2 1
#elif defined(__ARM_NEON) && defined(__aarch64__)
#include <arm_neon.h>
#define MCSLAM_ORB_HAVE_NEON 1
#endif

namespace mcslam::orb_detail {

struct ScalarU8x16 {
  static constexpr int kLanes = 16;
  uint8_t v[16];

  static ScalarU8x16 load(const uint8_t* p) {
    ScalarU8x16 r;
    std::memcpy(r.v, p, 16);
    return r;
  }
  static ScalarU8x16 splat(uint8_t x) {
    ScalarU8x16 r;
    std::fill(r.v, r.v + 16, x);
    return r;
  }
  void store(uint8_t* p) const { std::memcpy(p, v, 16); }
  bool anyNonZero() const {
    uint8_t acc = 0;
    for (uint8_t x : v) acc |= x;
    return acc != 0;
  }
  template <class Op>
  static ScalarU8x16 zip(const ScalarU8x16& a, const ScalarU8x16& b, Op op) {
    ScalarU8x16 r;
    for (int i = 0; i < 16; ++i) r.v[i] = static_cast<uint8_t>(op(int(a.v[i]), int(b.v[i])));
    return r;
  }
  friend ScalarU8x16 min(const ScalarU8x16& a, const ScalarU8x16& b) {
    return zip(a, b, [](int x, int y) { return std::min(x, y); });
  }
  friend ScalarU8x16 max(const ScalarU8x16& a, const ScalarU8x16& b) {
    return zip(a, b, [](int x, int y) { return std::max(x, y); });
  }
  // Saturating a - b and a + b.
  friend ScalarU8x16 subs(const ScalarU8x16& a, const ScalarU8x16& b) {
    return zip(a, b, [](int x, int y) { return std::max(x - y, 0); });
  }
  friend ScalarU8x16 adds(const ScalarU8x16& a, const ScalarU8x16& b) {
    return zip(a, b, [](int x, int y) { return std::min(x + y, 255); });
  }
  // a where a > t, else 0.
  friend ScalarU8x16 keepAbove(const ScalarU8x16& a, const ScalarU8x16& t) {
    return zip(a, t, [](int x, int y) { return x > y ? x : 0; });
  }
};

#if defined(MCSLAM_ORB_HAVE_SSE2)
struct NativeU8x16 {
  static constexpr int kLanes = 16;
  __m128i v;

  static NativeU8x16 load(const uint8_t* p) { return {_mm_loadu_si128(reinterpret_cast<const __m128i*>(p))}; }
  static NativeU8x16 splat(uint8_t x) { return {_mm_set1_epi8(static_cast<char>(x))}; }
  void store(uint8_t* p) const { _mm_storeu_si128(reinterpret_cast<__m128i*>(p), v); }
  bool anyNonZero() const { return _mm_movemask_epi8(_mm_cmpeq_epi8(v, _mm_setzero_si128())) != 0xFFFF; }
  friend NativeU8x16 min(NativeU8x16 a, NativeU8x16 b) { return {_mm_min_epu8(a.v, b.v)}; }
  friend NativeU8x16 max(NativeU8x16 a, NativeU8x16 b) { return {_mm_max_epu8(a.v, b.v)}; }
  friend NativeU8x16 subs(NativeU8x16 a, NativeU8x16 b) { return {_mm_subs_epu8(a.v, b.v)}; }
  friend NativeU8x16 adds(NativeU8x16 a, NativeU8x16 b) { return {_mm_adds_epu8(a.v, b.v)}; }
  friend NativeU8x16 keepAbove(NativeU8x16 a, NativeU8x16 t) {
    const __m128i not_above = _mm_cmpeq_epi8(_mm_subs_epu8(a.v, t.v), _mm_setzero_si128());
    return {_mm_andnot_si128(not_above, a.v)};
  }
};
#define MCSLAM_ORB_HAVE_NATIVE 1
#elif defined(MCSLAM_ORB_HAVE_NEON)
struct NativeU8x16 {
  static constexpr int kLanes = 16;
  uint8x16_t v;

  static NativeU8x16 load(const uint8_t* p) { return {vld1q_u8(p)}; }
  static NativeU8x16 splat(uint8_t x) { return {vdupq_n_u8(x)}; }
  void store(uint8_t* p) const { vst1q_u8(p, v); }
  bool anyNonZero() const { return vmaxvq_u8(v) != 0; }
  friend NativeU8x16 min(NativeU8x16 a, NativeU8x16 b) { return {vminq_u8(a.v, b.v)}; }
  friend NativeU8x16 max(NativeU8x16 a, NativeU8x16 b) { return {vmaxq_u8(a.v, b.v)}; }
  friend NativeU8x16 subs(NativeU8x16 a, NativeU8x16 b) { return {vqsubq_u8(a.v, b.v)}; }
  friend NativeU8x16 adds(NativeU8x16 a, NativeU8x16 b) { return {vqaddq_u8(a.v, b.v)}; }
  friend NativeU8x16 keepAbove(NativeU8x16 a, NativeU8x16 t) { return {vandq_u8(a.v, vcgtq_u8(a.v, t.v))}; }
};
#define MCSLAM_ORB_HAVE_NATIVE 1
#endif

}  // namespace mcslam::orb_detail
