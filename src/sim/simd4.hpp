#pragma once
// Four-lane float and int vectors (GCC vector extensions, which clang shares: plain SSE2 on x86-64, no target-specific
// intrinsics, so the build stays portable). The renderer works on four neighbouring pixels at a time: their rays share
// the camera centre, the tile's candidates and, most of the time, the surface they hit.
#include <cstdint>
#include <cstring>

namespace mcslam::sim {

typedef float f4 __attribute__((vector_size(16)));
typedef int32_t i4 __attribute__((vector_size(16)));
typedef uint32_t u4 __attribute__((vector_size(16)));

inline f4 splat(float v) { return f4{v, v, v, v}; }
inline f4 vmin(f4 a, f4 b) { return a < b ? a : b; }
inline f4 vmax(f4 a, f4 b) { return a > b ? a : b; }
inline f4 vmin(f4 a, float b) { return vmin(a, splat(b)); }
inline i4 vmin(i4 a, int b) {
  const i4 v = {b, b, b, b};
  return a < v ? a : v;
}
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
inline float vmin(float a, float b) { return a < b ? a : b; }
inline int vmin(int a, int b) { return a < b ? a : b; }
inline int toInt(float a) { return static_cast<int>(a); }
inline float gather(const float* base, int idx) { return base[idx]; }
inline float vabs(float a) { return a < 0.f ? -a : a; }
inline float toFloat(int a) { return static_cast<float>(a); }
inline int floorInt(float v) {
  const int i = static_cast<int>(v);
  return v < static_cast<float>(i) ? i - 1 : i;
}
inline int clampBelow(int v, int n) { return v < 0 ? 0 : (v >= n ? n - 1 : v); }
// Vectors are built and taken apart in registers: setting lanes one by one goes through the stack, and reading
// the 16 bytes back then stalls on store forwarding.
// {f(0), f(1), f(2), f(3)}
template <class F>
inline f4 lanes(F f) {
  return f4{f(0), f(1), f(2), f(3)};
}
inline f4 load4(const float* p) {
  f4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store4(float* p, f4 v) { std::memcpy(p, &v, sizeof v); }
// The first n (<= 4) floats only (at the right edge of an image whose width is no multiple of 4); other lanes 0.
inline f4 load4(const float* p, int n) {
  if (n == 4) return load4(p);
  float pad[4] = {};
  std::memcpy(pad, p, sizeof(float) * n);
  return load4(pad);
}
inline void store4(float* p, f4 v, int n) {
  float pad[4];
  store4(pad, v);
  std::memcpy(p, pad, sizeof(float) * n);
}
inline f4 gather(const float* base, i4 idx) { return f4{base[idx[0]], base[idx[1]], base[idx[2]], base[idx[3]]}; }
// Bytes base[idx[0]], ..., base[idx[3]] as floats.
inline f4 gatherBytes(const uint8_t* base, i4 idx) {
  return toFloat(i4{base[idx[0]], base[idx[1]], base[idx[2]], base[idx[3]]});
}
// Four rows (x, y, z, w) -> four columns: xs, ys, zs, ws.
inline void transpose4(const f4 r[4], f4 c[4]) {
  const f4 xy01 = __builtin_shufflevector(r[0], r[1], 0, 4, 1, 5),
           xy23 = __builtin_shufflevector(r[2], r[3], 0, 4, 1, 5);
  const f4 zw01 = __builtin_shufflevector(r[0], r[1], 2, 6, 3, 7),
           zw23 = __builtin_shufflevector(r[2], r[3], 2, 6, 3, 7);
  c[0] = __builtin_shufflevector(xy01, xy23, 0, 1, 4, 5);
  c[1] = __builtin_shufflevector(xy01, xy23, 2, 3, 6, 7);
  c[2] = __builtin_shufflevector(zw01, zw23, 0, 1, 4, 5);
  c[3] = __builtin_shufflevector(zw01, zw23, 2, 3, 6, 7);
}

// Whether any lane of a comparison result is true; the largest lane.
inline bool any(i4 m) {
  const i4 folded = m | __builtin_shufflevector(m, m, 2, 3, 0, 1);
  return (folded[0] | folded[1]) != 0;
}
inline float hmax(f4 a) {
  const f4 folded = vmax(a, __builtin_shufflevector(a, a, 2, 3, 0, 1));
  return folded[0] > folded[1] ? folded[0] : folded[1];
}
inline float sum(f4 a) { return (a[0] + a[1]) + (a[2] + a[3]); }

}  // namespace mcslam::sim
