#pragma once
// Image operations of the ORB pyramid, on caller-owned buffers (nothing allocates here).
#include <cstdint>

namespace mcslam::orb_detail {

struct Plane {  // a writable 8-bit image
  uint8_t* data = nullptr;
  int width = 0, height = 0, stride = 0;
  uint8_t* row(int y) const { return data + static_cast<long>(y) * stride; }
};

struct ConstPlane {
  const uint8_t* data = nullptr;
  int width = 0, height = 0, stride = 0;
  ConstPlane() = default;
  ConstPlane(const uint8_t* d, int w, int h, int s) : data(d), width(w), height(h), stride(s) {}
  ConstPlane(const Plane& p) : data(p.data), width(p.width), height(p.height), stride(p.stride) {}  // NOLINT
  const uint8_t* row(int y) const { return data + static_cast<long>(y) * stride; }
};

// Scratch for downscale(): column tables and one intermediate row, each at least the source width.
struct DownscaleScratch {
  int32_t* src_x;     // left source column of each destination column
  uint32_t* weights;  // its weights (left | right << 16), 1/256 units
  int16_t* row;       // vertically interpolated source row (width + 1)
};

// Bilinear resampling where destination pixel x samples source (x + 0.5) * ratio - 0.5 (pixel centres
// aligned, as the keypoint coordinates assume). dst.width/height say the destination size. Fixed point,
// 8-bit weights; use_simd picks the SSE2 or NEON path where there is one (identical results).
void downscale(const ConstPlane& src, const Plane& dst, float ratio, const DownscaleScratch& scratch, bool use_simd);

// 7x7 Gaussian, sigma 2 (the smoothing rBRIEF's tests assume), borders replicated. tmp: src-sized.
// use_simd: the AVX2 build where the CPU has it (identical results).
void gaussianBlur7(const ConstPlane& src, const Plane& dst, const Plane& tmp, bool use_simd = true);

}  // namespace mcslam::orb_detail
