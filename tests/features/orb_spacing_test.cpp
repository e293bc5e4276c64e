// The corner selector: strongest first with index order among equals, whichever sort it takes.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "orb_spacing.hpp"

using namespace mcslam::orb_detail;

namespace {

std::vector<Corner> randomCorners(int n, bool integer_scores, std::mt19937& rng) {
  std::vector<Corner> corners(n);
  for (Corner& c : corners) {
    c.x = static_cast<int>(rng() % 400);
    c.y = static_cast<int>(rng() % 300);
    const int s = 1 + static_cast<int>(rng() % 40);  // few levels: many ties
    c.score = integer_scores ? static_cast<float>(s) : static_cast<float>(s) + 0.25f;
  }
  return corners;
}

std::vector<Corner> select(const std::vector<Corner>& corners, float spacing, int budget) {
  SpacedSelector selector(static_cast<int>(corners.size()), 400, 300);
  std::vector<Corner> out(budget);
  out.resize(selector.select(corners, Rect{0, 0, 400, 300}, spacing, budget, out.data()));
  return out;
}

}  // namespace

// FAST scores (small integers) take a counting sort, other scores a comparison sort: shifting every score by
// the same fraction must not change which corners are taken, nor their order.
TEST(SpacedSelector, IntegerAndFractionalScoresSelectTheSameCornersInTheSameOrder) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 5; ++trial) {
    const std::vector<Corner> integer = randomCorners(3000, true, rng);
    std::vector<Corner> fractional = integer;
    for (Corner& c : fractional) c.score += 0.25f;
    for (const float spacing : {0.0f, 6.0f}) {
      const std::vector<Corner> a = select(integer, spacing, 500), b = select(fractional, spacing, 500);
      ASSERT_EQ(a.size(), 500u);
      ASSERT_EQ(a.size(), b.size());
      for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].x, b[i].x) << "trial " << trial << " rank " << i;
        EXPECT_EQ(a[i].y, b[i].y);
      }
      // Strongest first; among equal scores, input order.
      if (spacing == 0.0f) {
        for (std::size_t i = 1; i < a.size(); ++i) EXPECT_GE(a[i - 1].score, a[i].score);
      }
    }
  }
}
