#pragma once
// Keypoints of one image bucketed in square cells, for radius searches (projection matching).
// Sized once; build() is a counting sort and allocates nothing.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "mcslam/features/keypoint.hpp"

namespace mcslam {

class KeypointGrid {
 public:
  // What a radius search reads of a keypoint, stored contiguously in cell order: a search scans memory in
  // order instead of gathering keypoints by index.
  struct Entry {
    float x, y;
    int32_t index;  // in the FeatureSet
    int32_t octave;
  };

  KeypointGrid() = default;
  KeypointGrid(int width, int height, int cell_size, int max_keypoints)
      : cols_((width + cell_size - 1) / cell_size),
        rows_((height + cell_size - 1) / cell_size),
        cell_(cell_size),
        start_(cols_ * rows_ + 1),
        entries_(max_keypoints),
        cell_of_(max_keypoints) {}

  void build(const FeatureSet& set) {
    std::fill(start_.begin(), start_.end(), 0);
    for (int k = 0; k < set.count; ++k) {
      cell_of_[k] = cellOf(set.keypoints[k].x, set.keypoints[k].y);
      ++start_[cell_of_[k] + 1];
    }
    for (std::size_t i = 1; i < start_.size(); ++i) start_[i] += start_[i - 1];
    for (int k = 0; k < set.count; ++k) {
      const Keypoint& kp = set.keypoints[k];
      entries_[start_[cell_of_[k]]++] = Entry{kp.x, kp.y, k, kp.octave};
    }
    for (std::size_t i = start_.size() - 1; i > 0; --i) start_[i] = start_[i - 1];
    start_[0] = 0;
  }

  // Calls f(entry) for every keypoint whose cell touches the square of half-size r around (x, y), in cell
  // order and by keypoint index within a cell; the caller checks the exact distance.
  template <typename F>
  void forEachNear(double x, double y, double r, F&& f) const {
    const int x0 = std::max(0, static_cast<int>(std::floor((x - r) / cell_)));
    const int x1 = std::min(cols_ - 1, static_cast<int>(std::floor((x + r) / cell_)));
    const int y0 = std::max(0, static_cast<int>(std::floor((y - r) / cell_)));
    const int y1 = std::min(rows_ - 1, static_cast<int>(std::floor((y + r) / cell_)));
    for (int cy = y0; cy <= y1; ++cy) {
      // The cells of one grid row are contiguous in the entries.
      const Entry* e = entries_.data() + start_[cy * cols_ + x0];
      const Entry* end = entries_.data() + start_[cy * cols_ + x1 + 1];
      for (; e != end; ++e) f(*e);
    }
  }

 private:
  int cellOf(float x, float y) const {
    const int cx = std::clamp(static_cast<int>(x / static_cast<float>(cell_)), 0, cols_ - 1);
    const int cy = std::clamp(static_cast<int>(y / static_cast<float>(cell_)), 0, rows_ - 1);
    return cy * cols_ + cx;
  }

  int cols_ = 0, rows_ = 0, cell_ = 1;
  std::vector<int32_t> start_;
  std::vector<Entry> entries_;
  std::vector<int32_t> cell_of_;
};

}  // namespace mcslam
