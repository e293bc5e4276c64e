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
    const float a = bilinear(levels_[l0], u, v);
    if (f < 1.0f / 64.0f) return a;
    return a + f * (bilinear(levels_[l0 + 1], u, v) - a);
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
