#pragma once
// Grey 8-bit texture with a full mip chain (box-filtered), sampled trilinearly with wrap or clamp addressing.
// Values are display-referred (like a photograph); the renderer converts them to linear albedo.
#include <cmath>
#include <cstdint>
#include <memory>
#include <new>
#include <vector>

#include "simd4.hpp"

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
    int l0;
    float f;
    levelsFor(lod, l0, f);
    if (f < kBlendFloor) return bilinear(levels_[l0], u, v);
    return trilinear(levels_[l0], levels_[l0 + 1], u, v, f);
  }
  // Four points filtered at one lod (like a GPU, which picks the level per pixel quad): the level choice and the
  // address arithmetic are shared, only the texel reads are per lane.
  f4 sample4(f4 u, f4 v, float lod) const {
    int l0;
    float f;
    levelsFor(lod, l0, f);
    const f4 a = bilinear4(levels_[l0], u, v);
    if (f < kBlendFloor) return a;
    return a + f * (bilinear4(levels_[l0 + 1], u, v) - a);
  }

 private:
  // Levels stop at 8x8 texels (nothing is ever seen from far enough to need less).
  struct Level {
    int w, h;
    int shift;           // log2(w): row offsets of the four-lane path by shifting (SSE2 has no 32-bit multiply)
    float scale;         // 2^-level: level-0 texel units -> this level's
    std::size_t offset;  // into data_
  };

  // Blends closer to a level than this read that level alone (saves half the texel reads).
  static constexpr float kBlendFloor = 1.0f / 64.0f;

  void levelsFor(float lod, int& l0, float& f) const {
    const int top = static_cast<int>(levels_.size()) - 1;
    l0 = 0;
    f = 0.f;
    if (lod >= static_cast<float>(top)) {
      l0 = top;
    } else if (lod > 0.f) {
      l0 = static_cast<int>(lod);
      f = lod - static_cast<float>(l0);
    }
  }

  __attribute__((always_inline)) f4 bilinear4(const Level& L, f4 u, f4 v) const {
    i4 x0, y0, x1, y1;
    f4 fx, fy;
    texelCoords(L, u, v, x0, y0, x1, y1, fx, fy);
    const i4 r0 = y0 << L.shift, r1 = y1 << L.shift;
    const uint8_t* base = data_.get() + L.offset;
    const f4 t00 = gatherBytes(base, r0 + x0), t10 = gatherBytes(base, r0 + x1);
    const f4 t01 = gatherBytes(base, r1 + x0), t11 = gatherBytes(base, r1 + x1);
    const f4 a = t00 + fx * (t10 - t00);
    const f4 b = t01 + fx * (t11 - t01);
    return a + fy * (b - a);
  }
  __attribute__((always_inline)) float bilinear(const Level& L, float u, float v) const {
    int x0, y0, x1, y1;
    float fx, fy;
    texelCoords(L, u, v, x0, y0, x1, y1, fx, fy);
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
  // Texel pair (x0, x1) x (y0, y1) around level-0 coordinates (u, v) on level L, and the blend weights.
  // F, I: float and int for one point, f4 and i4 for four.
  template <class F, class I>
  __attribute__((always_inline)) void texelCoords(const Level& L, F u, F v, I& x0, I& y0, I& x1, I& y1, F& fx,
                                                  F& fy) const {
    const F x = u * L.scale - 0.5f, y = v * L.scale - 0.5f;
    x0 = floorInt(x);
    y0 = floorInt(y);
    fx = x - toFloat(x0);
    fy = y - toFloat(y0);
    if (wrap_) {
      x0 &= L.w - 1;
      y0 &= L.h - 1;
      x1 = (x0 + 1) & (L.w - 1);
      y1 = (y0 + 1) & (L.h - 1);
    } else {
      x1 = clampBelow(x0 + 1, L.w);
      y1 = clampBelow(y0 + 1, L.h);
      x0 = clampBelow(x0, L.w);
      y0 = clampBelow(y0, L.h);
    }
  }

  std::vector<Level> levels_;
  struct AlignedDelete {
    void operator()(uint8_t* p) const { ::operator delete[](p, std::align_val_t(64)); }
  };
  std::shared_ptr<uint8_t> data_;  // 64-byte aligned, shared (immutable) between copies
  bool wrap_ = true;
  float mean_ = 128.f;
};

}  // namespace mcslam::sim
