#pragma once
// Grey 8-bit texture with a full mip chain (box-filtered), sampled trilinearly with wrap or clamp addressing.
// Values are display-referred (like a photograph); the renderer converts them to linear albedo.
#include <cmath>
#include <cstdint>
#include <memory>
#include <new>
#include <vector>

namespace mcslam::sim {

class MipTexture {
 public:
  MipTexture() = default;
  // Width and height must be powers of two. pixels: row-major, width*height.
  MipTexture(int width, int height, const std::vector<uint8_t>& pixels, bool wrap);

  int width() const { return levels_.empty() ? 0 : levels_[0].w; }
  int height() const { return levels_.empty() ? 0 : levels_[0].h; }
  int levels() const { return static_cast<int>(levels_.size()); }
  bool wrap() const { return wrap_; }
  float mean() const { return mean_; }
  // Texel (x, y) of level l (in range).
  uint8_t texel(int l, int x, int y) const {
    return data_.get()[levels_[l].offset + static_cast<std::size_t>(y) * levels_[l].w + x];
  }

  // (u, v) in level-0 texel units (texel centres at i + 0.5); lod = log2 of the footprint in level-0 texels.
  float sample(float u, float v, float lod) const {
    const int top = static_cast<int>(levels_.size()) - 1;
    int l0 = 0;
    float f = 0.f;
    if (lod >= static_cast<float>(top)) {
      l0 = top;
    } else if (lod > 0.f) {
      l0 = static_cast<int>(lod);
      f = lod - static_cast<float>(l0);
    }
    if (f < 1.0f / 64.0f) return bilinear(levels_[l0], u, v);
    return trilinear(levels_[l0], levels_[l0 + 1], u, v, f);
  }

 private:
  // Levels stop at 8x8 texels (nothing is ever seen from far enough to need less).
  struct Level {
    int w, h;
    float scale;         // 2^-level: level-0 texel units -> this level's
    std::size_t offset;  // into data_
  };

  __attribute__((always_inline)) float bilinear(const Level& L, float u, float v) const {
    const float x = u * L.scale - 0.5f, y = v * L.scale - 0.5f;
    int x0 = floorInt(x), y0 = floorInt(y), x1, y1;
    const float fx = x - static_cast<float>(x0), fy = y - static_cast<float>(y0);
    if (wrap_) {
      x0 &= L.w - 1;
      y0 &= L.h - 1;
      x1 = (x0 + 1) & (L.w - 1);
      y1 = (y0 + 1) & (L.h - 1);
    } else {
      x1 = clampi(x0 + 1, L.w);
      y1 = clampi(y0 + 1, L.h);
      x0 = clampi(x0, L.w);
      y0 = clampi(y0, L.h);
    }
    const uint8_t* r0 = data_.get() + L.offset + static_cast<std::size_t>(y0) * L.w;
    const uint8_t* r1 = data_.get() + L.offset + static_cast<std::size_t>(y1) * L.w;
    const float t00 = r0[x0], t10 = r0[x1], t01 = r1[x0], t11 = r1[x1];
    const float a = t00 + fx * (t10 - t00);
    const float b = t01 + fx * (t11 - t01);
    return a + fy * (b - a);
  }
  // Both levels' bilinear lookups at once (the hot path of shading): the same float operations as bilinear() on
  // each, so the result is bit-identical, with a quarter of the int-to-float conversions and half the lerps.
  __attribute__((always_inline)) float trilinear(const Level& A, const Level& B, float u, float v, float f) const {
    typedef float f4 __attribute__((vector_size(16)));
    typedef int32_t i4 __attribute__((vector_size(16)));
    int ax0, ay0, ax1, ay1, bx0, by0, bx1, by1;
    float afx, afy, bfx, bfy;
    texelCoords(A, u, v, ax0, ay0, ax1, ay1, afx, afy);
    texelCoords(B, u, v, bx0, by0, bx1, by1, bfx, bfy);
    const uint8_t* a0 = data_.get() + A.offset + static_cast<std::size_t>(ay0) * A.w;
    const uint8_t* a1 = data_.get() + A.offset + static_cast<std::size_t>(ay1) * A.w;
    const uint8_t* b0 = data_.get() + B.offset + static_cast<std::size_t>(by0) * B.w;
    const uint8_t* b1 = data_.get() + B.offset + static_cast<std::size_t>(by1) * B.w;
    // Lanes: (row 0, row 1) of level A, then of level B.
    const f4 left = __builtin_convertvector((i4{a0[ax0], a1[ax0], b0[bx0], b1[bx0]}), f4);
    const f4 right = __builtin_convertvector((i4{a0[ax1], a1[ax1], b0[bx1], b1[bx1]}), f4);
    const f4 fx = {afx, afx, bfx, bfx};
    const f4 rows = left + fx * (right - left);
    const float a = rows[0] + afy * (rows[1] - rows[0]);
    const float b = rows[2] + bfy * (rows[3] - rows[2]);
    return a + f * (b - a);
  }
  __attribute__((always_inline)) void texelCoords(const Level& L, float u, float v, int& x0, int& y0, int& x1, int& y1,
                                                  float& fx, float& fy) const {
    const float x = u * L.scale - 0.5f, y = v * L.scale - 0.5f;
    x0 = floorInt(x);
    y0 = floorInt(y);
    fx = x - static_cast<float>(x0);
    fy = y - static_cast<float>(y0);
    if (wrap_) {
      x0 &= L.w - 1;
      y0 &= L.h - 1;
      x1 = (x0 + 1) & (L.w - 1);
      y1 = (y0 + 1) & (L.h - 1);
    } else {
      x1 = clampi(x0 + 1, L.w);
      y1 = clampi(y0 + 1, L.h);
      x0 = clampi(x0, L.w);
      y0 = clampi(y0, L.h);
    }
  }
  // std::floor is slow on the baseline x86-64 target (no SSE4.1 round instruction).
  static int floorInt(float v) {
    const int i = static_cast<int>(v);
    return v < static_cast<float>(i) ? i - 1 : i;
  }
  static int clampi(int v, int n) { return v < 0 ? 0 : (v >= n ? n - 1 : v); }

  std::vector<Level> levels_;
  struct AlignedDelete {
    void operator()(uint8_t* p) const { ::operator delete[](p, std::align_val_t(64)); }
  };
  std::shared_ptr<uint8_t> data_;  // 64-byte aligned, shared (immutable) between copies
  bool wrap_ = true;
  float mean_ = 128.f;
};

}  // namespace mcslam::sim
