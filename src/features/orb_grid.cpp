#include "orb_grid.hpp"

#include <algorithm>
#include <cstring>

namespace mcslam::orb_detail {

void collectLocalMaxima(const ConstPlane& scores, const Rect& rect, std::vector<Corner>& out) {
  const int stride = scores.stride;
  for (int y = rect.y0; y < rect.y1; ++y) {
    const uint8_t* row = scores.row(y);
    for (int x = rect.x0; x < rect.x1; x += 16) {
      // Most of the map is zero: skip 16 pixels at a time (reading past rect.x1 stays inside the
      // padded plane; only the lanes inside the rect are looked at).
      const int n = std::min(16, rect.x1 - x);
      uint64_t words[2];
      std::memcpy(words, row + x, sizeof words);
      if ((words[0] | words[1]) == 0) continue;
      for (int i = 0; i < n; ++i) {
        const uint8_t* p = row + x + i;
        const int s = *p;
        if (s == 0) continue;
        const bool is_max = s >= p[-stride - 1] && s >= p[-stride] && s >= p[-stride + 1] && s >= p[-1] &&
                            s > p[1] && s > p[stride - 1] && s > p[stride] && s > p[stride + 1];
        if (is_max && out.size() < out.capacity()) out.push_back({x + i, y, static_cast<float>(s)});
      }
    }
  }
}

Grid::Grid(const Rect& r, int cell_size) : region(r), cell(std::max(cell_size, 1)) {
  cols = r.empty() ? 0 : (r.x1 - r.x0 + cell - 1) / cell;
  rows = r.empty() ? 0 : (r.y1 - r.y0 + cell - 1) / cell;
}

Rect Grid::cellRect(int index) const {
  const int cx = index % cols, cy = index / cols;
  const int x0 = region.x0 + cx * cell, y0 = region.y0 + cy * cell;
  return {x0, y0, std::min(x0 + cell, region.x1), std::min(y0 + cell, region.y1)};
}

}  // namespace mcslam::orb_detail
