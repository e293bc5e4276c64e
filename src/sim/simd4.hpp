#pragma once
// Four-lane float and int vectors (GCC vector extensions: plain SSE2 on x86-64, no target-specific intrinsics,
// so the build stays portable). The renderer works on four neighbouring pixels at a time: their rays share the
// camera centre, the tile's candidates and, most of the time, the surface they hit.
#include <cstdint>

namespace mcslam::sim {

typedef float f4 __attribute__((vector_size(16)));
typedef int32_t i4 __attribute__((vector_size(16)));
typedef uint32_t u4 __attribute__((vector_size(16)));

inline f4 splat(float v) { return f4{v, v, v, v}; }
inline f4 vmin(f4 a, f4 b) { return a < b ? a : b; }
inline f4 vmax(f4 a, f4 b) { return a > b ? a : b; }
inline f4 vmin(f4 a, float b) { return vmin(a, splat(b)); }
inline f4 vabs(f4 a) { return a < 0.f ? -a : a; }
inline f4 toFloat(i4 a) { return __builtin_convertvector(a, f4); }
// Truncation towards zero (cvttps2dq).
inline i4 toInt(f4 a) { return __builtin_convertvector(a, i4); }
// floor as an int: std::floor is slow on the baseline x86-64 target (no SSE4.1 round instruction).
inline i4 floorInt(f4 v) {
  const i4 i = toInt(v);
  return i + (v < toFloat(i));  // a true comparison is -1
}
// v clamped to [0, n).
inline i4 clampBelow(i4 v, int n) {
  const i4 zero = {0, 0, 0, 0}, last = zero + (n - 1);
  v = v < zero ? zero : v;
  return v > last ? last : v;
}
inline f4 vmax(f4 a, float b) { return vmax(a, splat(b)); }
// Scalar twins, so that code templated on the lane type reads the same for one pixel and for four.
inline float vmax(float a, float b) { return a > b ? a : b; }
inline float vabs(float a) { return a < 0.f ? -a : a; }
inline float toFloat(int a) { return static_cast<float>(a); }
inline int floorInt(float v) {
  const int i = static_cast<int>(v);
  return v < static_cast<float>(i) ? i - 1 : i;
}
inline int clampBelow(int v, int n) { return v < 0 ? 0 : (v >= n ? n - 1 : v); }
inline float sum(f4 a) { return (a[0] + a[1]) + (a[2] + a[3]); }

}  // namespace mcslam::sim
