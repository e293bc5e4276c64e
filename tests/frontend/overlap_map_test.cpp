#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "mcslam/features/overlap_map.hpp"
#include "synthetic_rigs.hpp"

using namespace mcslam;

namespace {

// Every point visible in two cameras must be found where the map says: its cell in camera j is a
// candidate of its cell in camera i. Returns the share of such (point, pair) checks that pass.
double recall(const Rig& rig, const OverlapMap& map, double min_depth, double max_depth, int* checks) {
  std::mt19937 rng(11);
  const auto scene = test::randomScene(rig, 20000, min_depth, max_depth, rng);
  int ok = 0, n = 0;
  for (const auto& sp : scene) {
    for (int i = 0; i < rig.size(); ++i) {
      for (int j = 0; j < rig.size(); ++j) {
        if (i == j || !sp.visible[i] || !sp.visible[j]) continue;
        const int ci = map.grid(i).cellOf(sp.uv[i].x(), sp.uv[i].y());
        const int cj = map.grid(j).cellOf(sp.uv[j].x(), sp.uv[j].y());
        const auto cand = map.candidates(i, j, ci);
        ++n;
        ok += std::find(cand.begin(), cand.end(), cj) != cand.end() ? 1 : 0;
      }
    }
  }
  *checks = n;
  return n ? static_cast<double>(ok) / n : 0.0;
}

}  // namespace

TEST(OverlapMap, FiveFrontCamerasAllOverlapAndNoTrueMatchIsMissed) {
  const Rig rig = test::isecRig();
  OverlapOptions opt;
  const OverlapMap map(rig, opt);
  EXPECT_EQ(map.overlappingPairs().size(), 10u);
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 5; ++j) {
      if (i == j) continue;
      EXPECT_TRUE(map.overlaps(i, j));
      EXPECT_GT(map.overlapFraction(i, j), 0.6) << i << "-" << j;
    }
  }
  int checks = 0;
  EXPECT_EQ(recall(rig, map, opt.min_depth, opt.max_depth, &checks), 1.0);
  EXPECT_GT(checks, 10000);
  // The search stays a band, not the whole image.
  const auto cand = map.candidates(0, 1, map.grid(0).cellOf(360, 270));
  EXPECT_LT(static_cast<int>(cand.size()), map.grid(1).cells() / 4);
}

TEST(OverlapMap, RingOfEightOverlapsOnlyWithItsNeighbours) {
  const Rig rig = test::ring8Rig(70.0);
  OverlapOptions opt;
  opt.min_depth = 1.0;
  const OverlapMap map(rig, opt);
  for (int i = 0; i < 8; ++i) {
    EXPECT_TRUE(map.overlaps(i, (i + 1) % 8)) << i;
    EXPECT_TRUE(map.overlaps(i, (i + 7) % 8)) << i;
    EXPECT_FALSE(map.overlaps(i, (i + 4) % 8)) << i;  // opposite cameras never see the same point
    EXPECT_FALSE(map.overlaps(i, (i + 2) % 8)) << i;  // 90 degrees apart with 70 degree lenses
    EXPECT_LT(map.overlapFraction(i, (i + 1) % 8), 0.6);
  }
  EXPECT_EQ(map.overlappingPairs().size(), 8u);
  int checks = 0;
  EXPECT_EQ(recall(rig, map, opt.min_depth, opt.max_depth, &checks), 1.0);
  EXPECT_GT(checks, 1000);
}

TEST(OverlapMap, DepthRangeMatters) {
  // Far-only scenes shrink the epipolar band: fewer candidates than with near points allowed.
  const Rig rig = test::isecRig();
  OverlapOptions near_opt, far_opt;
  far_opt.min_depth = 5.0;
  const OverlapMap near_map(rig, near_opt), far_map(rig, far_opt);
  const int cell = near_map.grid(0).cellOf(360, 270);
  EXPECT_LT(far_map.candidates(0, 4, cell).size(), near_map.candidates(0, 4, cell).size());
}
