#include "orb_spacing.hpp"

#include <algorithm>
#include <cmath>

namespace mcslam::orb_detail {
namespace {
// Buckets are never smaller than this (bounds their number for any spacing).
constexpr int kMinBucket = 4;
}  // namespace

SpacedSelector::SpacedSelector(int max_corners, int max_width, int max_height)
    : max_width_(max_width),
      max_height_(max_height),
      order_(static_cast<size_t>(max_corners)),
      bucket_head_(static_cast<size_t>((max_width / kMinBucket + 2) * (max_height / kMinBucket + 2))),
      next_(static_cast<size_t>(max_corners)),
      used_(static_cast<size_t>(max_corners)) {}

bool SpacedSelector::farFromTaken(const Corner& c, const Corner* taken, float spacing) const {
  const float limit = spacing * spacing;
  const int bx = (c.x - origin_x_) / bucket_size_, by = (c.y - origin_y_) / bucket_size_;
  for (int y = std::max(by - 1, 0); y <= std::min(by + 1, bucket_rows_ - 1); ++y) {
    for (int x = std::max(bx - 1, 0); x <= std::min(bx + 1, bucket_cols_ - 1); ++x) {
      for (int i = bucket_head_[static_cast<size_t>(y * bucket_cols_ + x)]; i >= 0; i = next_[static_cast<size_t>(i)]) {
        const float dx = static_cast<float>(taken[i].x - c.x), dy = static_cast<float>(taken[i].y - c.y);
        if (dx * dx + dy * dy < limit) return false;
      }
    }
  }
  return true;
}

// Strongest first, the index breaking ties (so the order never depends on a sort's internals). FAST scores are
// small integers: a counting sort over them is linear, and gives the order the comparison sort gives.
void SpacedSelector::sortByScore(std::span<const Corner> corners) {
  const int n = static_cast<int>(corners.size());
  bool small_integers = true;
  for (int i = 0; i < n && small_integers; ++i) {
    const float s = corners[i].score;
    small_integers = s >= 0.f && s < static_cast<float>(kScoreLevels) && s == std::floor(s);
  }
  if (!small_integers) {
    for (int i = 0; i < n; ++i) order_[static_cast<size_t>(i)] = i;
    std::sort(order_.begin(), order_.begin() + n, [&](int a, int b) {
      return corners[a].score != corners[b].score ? corners[a].score > corners[b].score : a < b;
    });
    return;
  }
  int start[kScoreLevels + 1] = {};
  for (int i = 0; i < n; ++i) ++start[kScoreLevels - static_cast<int>(corners[i].score)];  // descending
  for (int k = 0; k < kScoreLevels; ++k) start[k + 1] += start[k];
  for (int i = 0; i < n; ++i)
    order_[static_cast<size_t>(start[kScoreLevels - 1 - static_cast<int>(corners[i].score)]++)] = i;
}

int SpacedSelector::select(std::span<const Corner> corners, const Rect& region, float spacing, int budget,
                           Corner* out) {
  const int n = static_cast<int>(corners.size());
  if (budget <= 0 || n == 0 || n > static_cast<int>(order_.size())) return 0;
  sortByScore(corners);
  std::fill(used_.begin(), used_.begin() + n, 0);
  origin_x_ = region.x0;
  origin_y_ = region.y0;

  int taken = 0;
  for (const float pass_spacing : {spacing, spacing * 0.5f, 0.0f}) {
    if (taken >= budget) break;
    const bool spaced = pass_spacing >= 1.0f;
    if (spaced) {
      // Buckets at least as wide as the spacing: a conflict can only sit in the 3x3 neighbourhood.
      bucket_size_ = std::max(kMinBucket, static_cast<int>(std::ceil(pass_spacing)));
      bucket_cols_ = (region.x1 - region.x0) / bucket_size_ + 1;
      bucket_rows_ = (region.y1 - region.y0) / bucket_size_ + 1;
      std::fill(bucket_head_.begin(), bucket_head_.begin() + bucket_cols_ * bucket_rows_, -1);
      for (int t = 0; t < taken; ++t) {
        const int b = ((out[t].y - origin_y_) / bucket_size_) * bucket_cols_ + (out[t].x - origin_x_) / bucket_size_;
        next_[static_cast<size_t>(t)] = bucket_head_[static_cast<size_t>(b)];
        bucket_head_[static_cast<size_t>(b)] = t;
      }
    }
    for (int k = 0; k < n && taken < budget; ++k) {
      const int i = order_[static_cast<size_t>(k)];
      if (used_[static_cast<size_t>(i)]) continue;
      const Corner& c = corners[static_cast<size_t>(i)];
      if (spaced && !farFromTaken(c, out, pass_spacing)) continue;
      used_[static_cast<size_t>(i)] = 1;
      out[taken] = c;
      if (spaced) {
        const int b = ((c.y - origin_y_) / bucket_size_) * bucket_cols_ + (c.x - origin_x_) / bucket_size_;
        next_[static_cast<size_t>(taken)] = bucket_head_[static_cast<size_t>(b)];
        bucket_head_[static_cast<size_t>(b)] = taken;
      }
      ++taken;
    }
  }
  return taken;
}

}  // namespace mcslam::orb_detail
