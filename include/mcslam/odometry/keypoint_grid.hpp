#pragma once
// Keypoints of one image bucketed in square cells, for radius searches (projection matching).
// Sized once; build() is a counting sort and allocates nothing.
#include <cmath>
#include <cstdint>
#include <vector>

#include "mcslam/features/keypoint.hpp"

namespace mcslam {

class KeypointGrid {
 public:
  KeypointGrid() = default;
  KeypointGrid(int width, int height, int cell_size, int max_keypoints)
      : cols_((width + cell_size - 1) / cell_size),
        rows_((height + cell_size - 1) / cell_size),
        cell_(cell_size),
        start_(cols_ * rows_ + 1),
        items_(max_keypoints),
        cell_of_(max_keypoints) {}

  void build(const FeatureSet& set) {
    std::fill(start_.begin(), start_.end(), 0);
    count_ = set.count;
    for (int k = 0; k < set.count; ++k) {
      cell_of_[k] = cellOf(set.keypoints[k].x, set.keypoints[k].y);
      ++start_[cell_of_[k] + 1];
    }
    for (std::size_t i = 1; i < start_.size(); ++i) start_[i] += start_[i - 1];
    for (int k = 0; k < set.count; ++k) items_[start_[cell_of_[k]]++] = k;
    for (std::size_t i = start_.size() - 1; i > 0; --i) start_[i] = start_[i - 1];
    start_[0] = 0;
  }

  // Calls f(keypoint index) for every keypoint whose cell touches the square of half-size r around (x, y);
  // the caller checks the exact distance.
  template <typename F>
  void forEachNear(double x, double y, double r, F&& f) const {
    const int x0 = std::max(0, static_cast<int>(std::floor((x - r) / cell_)));
    const int x1 = std::min(cols_ - 1, static_cast<int>(std::floor((x + r) / cell_)));
    const int y0 = std::max(0, static_cast<int>(std::floor((y - r) / cell_)));
    const int y1 = std::min(rows_ - 1, static_cast<int>(std::floor((y + r) / cell_)));
    for (int cy = y0; cy <= y1; ++cy) {
      for (int cx = x0; cx <= x1; ++cx) {
        const int c = cy * cols_ + cx;
        for (int i = start_[c]; i < start_[c + 1]; ++i) f(items_[i]);
      }
    }
  }

 private:
  int cellOf(float x, float y) const {
    const int cx = std::clamp(static_cast<int>(x / cell_), 0, cols_ - 1);
    const int cy = std::clamp(static_cast<int>(y / cell_), 0, rows_ - 1);
    return cy * cols_ + cx;
  }

  int cols_ = 0, rows_ = 0, cell_ = 1, count_ = 0;
  std::vector<int32_t> start_, items_, cell_of_;
};

}  // namespace mcslam
