// Repetitions along the epipolar direction on synthetic images: a pattern that repeats along the line, the same
// pattern across it only, a random texture, and a repetition beyond the searched offsets.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mcslam/features/epipolar_uniqueness.hpp"

using namespace mcslam;

namespace {

// Random values on a 2-pixel lattice, bilinearly interpolated (detail like that around a FAST corner, no
// repetition), or tiled with period (px, py) in pixels (0: not tiled that way).
Image texture(unsigned seed, int px, int py) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> u(40, 215);
  constexpr int kCell = 2, kW = 256 / kCell + 2, kH = 160 / kCell + 2;
  static int lattice[kH][kW];
  for (auto& row : lattice) {
    for (int& v : row) v = u(rng);
  }
  Image im(256, 160);
  for (int y = 0; y < im.height(); ++y) {
    for (int x = 0; x < im.width(); ++x) {
      const double tx = (px > 0 ? x % px : x) / static_cast<double>(kCell);
      const double ty = (py > 0 ? y % py : y) / static_cast<double>(kCell);
      const int ix = static_cast<int>(tx), iy = static_cast<int>(ty);
      const double ax = tx - ix, ay = ty - iy;
      const double top = lattice[iy][ix] + ax * (lattice[iy][ix + 1] - lattice[iy][ix]);
      const double bottom = lattice[iy + 1][ix] + ax * (lattice[iy + 1][ix + 1] - lattice[iy + 1][ix]);
      im.row(y)[x] = static_cast<uint8_t>(std::lround(top + ay * (bottom - top)));
    }
  }
  return im;
}

EpipolarRepeatSearch along(const Vec2& direction, int lowest, int highest) {
  EpipolarRepeatSearch s;
  s.uv = Vec2(128.3, 80.6);
  s.direction = direction.normalized();
  s.spacing = 1.0;
  s.lowest = lowest;
  s.highest = highest;
  return s;
}

}  // namespace

// Offsets where the patch at the match recurs (at most 8).
int repeats(const Image& im, const Vec2& direction, int lowest, int highest, int* offsets) {
  return repeatsAlongEpipolar(im.view(), along(direction, lowest, highest), 3, 0.85, offsets, 8);
}

TEST(EpipolarUniqueness, APatternRepeatingAlongTheLineIsFoundAtItsPeriod) {
  const Image im = texture(1, 37, 0);  // repeats every 37 px in x
  int offsets[8];
  ASSERT_EQ(repeats(im, Vec2(1, 0), -60, 60, offsets), 2);  // one period either side
  EXPECT_NEAR(offsets[0], 37, 1);
  EXPECT_NEAR(offsets[1], -37, 1);
  ASSERT_EQ(repeats(im, Vec2(1, 0), 0, 80, offsets), 2);  // one side only: two periods
  EXPECT_NEAR(offsets[1], 74, 1);
  // A slanted line meets the repetition elsewhere than along x: the same texture gives no second match.
  EXPECT_EQ(repeats(im, Vec2(1, 1), -60, 60, offsets), 0);
}

TEST(EpipolarUniqueness, AUniqueTextureOrARepetitionAcrossTheLineIsNot) {
  int offsets[8];
  EXPECT_EQ(repeats(texture(2, 0, 0), Vec2(1, 0), -90, 90, offsets), 0);
  EXPECT_EQ(repeats(texture(3, 0, 29), Vec2(1, 0), -90, 90, offsets), 0);
}

TEST(EpipolarUniqueness, OnlyTheSearchedOffsetsCount) {
  const Image im = texture(4, 37, 0);
  int offsets[8];
  EXPECT_EQ(repeats(im, Vec2(1, 0), -30, 30, offsets), 0);  // within one period
  EXPECT_EQ(repeats(im, Vec2(1, 0), 0, 0, offsets), 0);
  EXPECT_EQ(repeatsAlongEpipolar(im.view(), along(Vec2(1, 0), -80, 80), 3, 0.85, offsets, 1), 1);  // capacity
}
