#pragma once
// Corners, their 3x3 non-maximum suppression, and the grid of cells of the low-threshold fallback.
#include <cstdint>
#include <vector>

#include "orb_pyramid.hpp"

namespace mcslam::orb_detail {

struct Corner {
  int x, y;
  float score;
};

struct Rect {
  int x0, y0, x1, y1;  // [x0, x1) x [y0, y1)
  bool empty() const { return x1 <= x0 || y1 <= y0; }
};

// Appends the corners of `rect` (non-zero scores) that are 3x3 local maxima of the score map. Ties go
// to the later pixel in raster order, so no two kept corners touch: at most one per 2x2 block, which
// bounds the list (maxLocalMaxima). The one-pixel frame around the scored area must be zero.
// Never grows `out` beyond its capacity. Reads up to 16 bytes past rect.x1 (the planes are padded).
// use_simd: the SSE2 or NEON kernel where the build has it; both give the same corners in the same order.
void collectLocalMaxima(const ConstPlane& scores, const Rect& rect, std::vector<Corner>& out, bool use_simd = true);
inline int maxLocalMaxima(int width, int height) { return ((width + 1) / 2) * ((height + 1) / 2); }

// Square cells over a region (the last row and column may be narrower).
struct Grid {
  Rect region{0, 0, 0, 0};
  int cell = 1, cols = 0, rows = 0;
  Grid() = default;
  Grid(const Rect& r, int cell_size);
  int cells() const { return cols * rows; }
  int cellOf(int x, int y) const { return ((y - region.y0) / cell) * cols + (x - region.x0) / cell; }
  Rect cellRect(int index) const;
  static int maxCells(int width, int height, int cell_size) {
    return (width / cell_size + 1) * (height / cell_size + 1);
  }
};

}  // namespace mcslam::orb_detail
