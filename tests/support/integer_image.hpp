#pragma once
// Test images made with integer arithmetic only (no libm, nothing a compiler could fuse or round differently): the
// same bytes on every architecture, so that a feature's output on them can be compared with values recorded on
// another machine (the cross-architecture tests).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "mcslam/core/image.hpp"

namespace mcslam::test {

// Value noise over five octaves (bilinear on hashed lattices) with rectangles and discs of sharp edges on top.
inline Image integerFrame(int width, int height, uint32_t seed) {
  auto hash = [seed](uint32_t a, uint32_t b, uint32_t c) {
    uint32_t h = seed ^ (a * 0x9E3779B1u) ^ (b * 0x85EBCA77u) ^ (c * 0xC2B2AE3Du);
    h ^= h >> 15;
    h *= 0x2C1B3C6Du;
    h ^= h >> 12;
    h *= 0x297A2D39u;
    h ^= h >> 15;
    return h;
  };
  auto lattice = [&](int octave, int i, int j) {
    return static_cast<int>(hash(static_cast<uint32_t>(i), static_cast<uint32_t>(j), static_cast<uint32_t>(octave)) &
                            255u) -
           128;
  };
  constexpr int kPeriod[5] = {64, 32, 16, 8, 4};
  constexpr int kAmplitude[5] = {60, 44, 32, 22, 14};
  std::vector<int> v(static_cast<size_t>(width) * static_cast<size_t>(height), 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      int sum = 0;
      for (int o = 0; o < 5; ++o) {
        const int p = kPeriod[o], i = x / p, j = y / p, fx = x % p, fy = y % p;
        const int top = lattice(o, i, j) * (p - fx) + lattice(o, i + 1, j) * fx;
        const int bottom = lattice(o, i, j + 1) * (p - fx) + lattice(o, i + 1, j + 1) * fx;
        sum += kAmplitude[o] * ((top * (p - fy) + bottom * fy) / (p * p)) / 128;
      }
      v[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)] = sum;
    }
  }
  const int shapes = width * height / 2500;
  for (int s = 0; s < shapes; ++s) {
    const uint32_t h = hash(static_cast<uint32_t>(s), 0xABCDu, 99u);
    const int cx = static_cast<int>(h % static_cast<uint32_t>(width));
    const int cy = static_cast<int>((h >> 12) % static_cast<uint32_t>(height));
    const uint32_t g = hash(static_cast<uint32_t>(s), 0x1234u, 98u);
    const int r = 3 + static_cast<int>(g % 22u), level = static_cast<int>((g >> 8) % 161u) - 80;
    const bool disc = ((g >> 20) & 1u) != 0;
    const int rx = r, ry = disc ? r : 3 + static_cast<int>((g >> 24) % 22u);
    for (int y = std::max(cy - ry, 0); y <= std::min(cy + ry, height - 1); ++y) {
      for (int x = std::max(cx - rx, 0); x <= std::min(cx + rx, width - 1); ++x) {
        if (disc && (x - cx) * (x - cx) + (y - cy) * (y - cy) > r * r) continue;
        v[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)] += level;
      }
    }
  }
  Image image(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const int value = 128 + v[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)];
      image.row(y)[x] = static_cast<uint8_t>(std::clamp(value, 0, 255));
    }
  }
  return image;
}

// FNV-1a over bytes: a digest of a result that two machines can compare.
struct Fnv1a {
  uint64_t h = 0xcbf29ce484222325ull;
  void bytes(const void* data, size_t n) {
    const auto* p = static_cast<const uint8_t*>(data);
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 0x100000001b3ull;
  }
  template <class T>
  void add(const T& value) {
    bytes(&value, sizeof value);
  }
};

}  // namespace mcslam::test
