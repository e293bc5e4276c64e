#include "mip_texture.hpp"

#include <algorithm>
#include <stdexcept>

namespace mcslam::sim {

namespace {
bool isPowerOfTwo(int v) { return v > 0 && (v & (v - 1)) == 0; }
}  // namespace

MipTexture::MipTexture(int width, int height, const std::vector<uint8_t>& pixels, bool wrap) : wrap_(wrap) {
  if (!isPowerOfTwo(width) || !isPowerOfTwo(height) || width < 8 || height < 8 ||
      pixels.size() != static_cast<std::size_t>(width) * height) {
    throw std::invalid_argument("MipTexture: sizes must be powers of two, at least 8, and match the pixels");
  }
  std::size_t total = 0;
  float scale = 1.f;
  for (int w = width, h = height; w >= 8 && h >= 8; w /= 2, h /= 2, scale *= 0.5f) {
    Level L;
    L.w = w;
    L.h = h;
    L.shift = __builtin_ctz(static_cast<unsigned>(w));
    L.scale = scale;
    L.offset = total;
    levels_.push_back(L);
    total += static_cast<std::size_t>(w) * h;
  }
  data_.reset(static_cast<uint8_t*>(::operator new[](total, std::align_val_t(64))), AlignedDelete{});
  uint8_t* out = data_.get();
  double sum = 0;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const uint8_t v = pixels[static_cast<std::size_t>(y) * width + x];
      out[static_cast<std::size_t>(y) * width + x] = v;
      sum += v;
    }
  }
  mean_ = static_cast<float>(sum / static_cast<double>(pixels.size()));
  // Each level averages 2x2 (or 2x1) texels of the one above, rounding to nearest.
  for (std::size_t l = 1; l < levels_.size(); ++l) {
    const Level& src = levels_[l - 1];
    const Level& dst = levels_[l];
    for (int y = 0; y < dst.h; ++y) {
      const uint8_t* s0 = out + src.offset + static_cast<std::size_t>(2 * y) * src.w;
      const uint8_t* s1 = s0 + src.w;
      uint8_t* d = out + dst.offset + static_cast<std::size_t>(y) * dst.w;
      for (int x = 0; x < dst.w; ++x) {
        d[x] = static_cast<uint8_t>((s0[2 * x] + s0[2 * x + 1] + s1[2 * x] + s1[2 * x + 1] + 2) / 4);
      }
    }
  }
}

}  // namespace mcslam::sim
