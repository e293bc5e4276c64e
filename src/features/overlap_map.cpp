#include "mcslam/features/overlap_map.hpp"

#include <algorithm>
#include <cmath>

#include "mcslam/core/error.hpp"

namespace mcslam {

CellGrid::CellGrid(int image_width, int image_height, int cell_size_px)
    : cols((image_width + cell_size_px - 1) / cell_size_px),
      rows((image_height + cell_size_px - 1) / cell_size_px),
      cell_size(cell_size_px),
      width(image_width),
      height(image_height) {}

OverlapMap::OverlapMap(const Rig& rig, const OverlapOptions& options) : cameras_(rig.size()), options_(options) {
  if (options.cell_size_px < 4) throw InputError("overlap: cell_size_px must be at least 4");
  if (!(options.min_depth > 0 && options.max_depth > options.min_depth)) {
    throw InputError("overlap: need 0 < min_depth < max_depth");
  }
  if (options.depth_samples < 2 || options.samples_per_cell < 1 || options.dilate_cells < 0) {
    throw InputError("overlap: depth_samples >= 2, samples_per_cell >= 1 and dilate_cells >= 0 required");
  }
  for (const RigCamera& c : rig.cameras) grids_.emplace_back(c.model.width(), c.model.height(), options.cell_size_px);
  pairs_.resize(static_cast<std::size_t>(cameras_) * cameras_);
  for (int i = 0; i < cameras_; ++i) {
    for (int j = 0; j < cameras_; ++j) {
      if (i != j) computePair(rig, i, j);
    }
  }
  for (int i = 0; i < cameras_; ++i) {
    for (int j = i + 1; j < cameras_; ++j) {
      if (overlaps(i, j) || overlaps(j, i)) overlapping_pairs_.emplace_back(i, j);
    }
  }
}

namespace {

// Clips the segment a-b to the rectangle [lo, hi] (Liang-Barsky); false when it lies outside.
bool clipSegment(Vec2& a, Vec2& b, const Vec2& lo, const Vec2& hi) {
  double t0 = 0.0, t1 = 1.0;
  const Vec2 d = b - a;
  const double p[4] = {-d.x(), d.x(), -d.y(), d.y()};
  const double q[4] = {a.x() - lo.x(), hi.x() - a.x(), a.y() - lo.y(), hi.y() - a.y()};
  for (int k = 0; k < 4; ++k) {
    if (p[k] == 0.0) {
      if (q[k] < 0.0) return false;
      continue;
    }
    const double r = q[k] / p[k];
    if (p[k] < 0.0)
      t0 = std::max(t0, r);
    else
      t1 = std::min(t1, r);
    if (t0 > t1) return false;
  }
  const Vec2 a0 = a;
  a = a0 + t0 * d;
  b = a0 + t1 * d;
  return true;
}

// Marks every cell a straight pixel segment passes through, stepping at a quarter cell so that no
// crossed cell is skipped. The segment is clipped to the image first: projections of near points can
// land far outside it.
void markSegment(const CellGrid& g, Vec2 a, Vec2 b, std::vector<uint8_t>& mark) {
  if (!clipSegment(a, b, Vec2(-0.5, -0.5), Vec2(g.width - 0.5, g.height - 0.5))) return;
  const double len = (b - a).norm();
  const int steps = std::max(1, static_cast<int>(std::ceil(len / (0.25 * g.cell_size))));
  for (int s = 0; s <= steps; ++s) {
    const Vec2 p = a + (b - a) * (static_cast<double>(s) / steps);
    const int c = g.cellOf(std::clamp(p.x(), -0.5, g.width - 0.51), std::clamp(p.y(), -0.5, g.height - 0.51));
    if (c >= 0) mark[c] = 1;
  }
}

}  // namespace

void OverlapMap::computePair(const Rig& rig, int i, int j) {
  const CellGrid& gi = grids_[i];
  const CellGrid& gj = grids_[j];
  const CameraModel& mi = rig.model(i);
  const CameraModel& mj = rig.model(j);
  const SE3 T_j_i = rig.T_b_c(j).inverse() * rig.T_b_c(i);
  const OverlapOptions& o = options_;

  std::vector<uint8_t> hit(gj.cells());
  std::vector<uint8_t> grown(gj.cells());
  Pair& pair = pairs_[i * cameras_ + j];
  std::vector<int32_t> offsets(gi.cells() + 1, 0);
  std::vector<int32_t> cells;
  int overlapping_cells = 0;

  for (int cell = 0; cell < gi.cells(); ++cell) {
    std::fill(hit.begin(), hit.end(), 0);
    const int cx = cell % gi.cols, cy = cell / gi.cols;
    for (int sy = 0; sy < o.samples_per_cell; ++sy) {
      for (int sx = 0; sx < o.samples_per_cell; ++sx) {
        // Sample pixels spread over the cell, its borders included.
        const double fx = o.samples_per_cell == 1 ? 0.5 : static_cast<double>(sx) / (o.samples_per_cell - 1);
        const double fy = o.samples_per_cell == 1 ? 0.5 : static_cast<double>(sy) / (o.samples_per_cell - 1);
        const double px = std::min<double>(gi.width - 1, cx * gi.cell_size + fx * (gi.cell_size - 1));
        const double py = std::min<double>(gi.height - 1, cy * gi.cell_size + fy * (gi.cell_size - 1));
        Vec3 bearing;
        if (!mi.unproject(Vec2(px, py), bearing)) continue;
        bool have_prev = false;
        Vec2 prev = Vec2::Zero();  // (read only when have_prev)
        for (int k = 0; k < o.depth_samples; ++k) {
          const double inv = 1.0 / o.min_depth + (1.0 / o.max_depth - 1.0 / o.min_depth) * k / (o.depth_samples - 1);
          const Vec3 pj = T_j_i * (bearing / inv);
          Vec2 uv;
          if (!mj.project(pj, uv)) {
            have_prev = false;
            continue;
          }
          if (have_prev)
            markSegment(gj, prev, uv, hit);
          else if (const int c = gj.cellOf(uv.x(), uv.y()); c >= 0)
            hit[c] = 1;
          prev = uv;
          have_prev = true;
        }
      }
    }
    overlapping_cells += std::find(hit.begin(), hit.end(), 1) != hit.end() ? 1 : 0;
    // Dilate: keypoint noise and calibration error move matches across cell borders.
    std::fill(grown.begin(), grown.end(), 0);
    for (int c = 0; c < gj.cells(); ++c) {
      if (!hit[c]) continue;
      const int x = c % gj.cols, y = c / gj.cols;
      for (int dy = -o.dilate_cells; dy <= o.dilate_cells; ++dy) {
        for (int dx = -o.dilate_cells; dx <= o.dilate_cells; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx >= 0 && yy >= 0 && xx < gj.cols && yy < gj.rows) grown[yy * gj.cols + xx] = 1;
        }
      }
    }
    for (int c = 0; c < gj.cells(); ++c) {
      if (grown[c]) cells.push_back(c);
    }
    offsets[cell + 1] = static_cast<int32_t>(cells.size());
  }
  if (!cells.empty()) {
    cells.shrink_to_fit();  // kept for the whole run: not the push_back growth's spare capacity
    pair.offsets = std::move(offsets);
    pair.cells = std::move(cells);
  }
  pair.fraction = static_cast<double>(overlapping_cells) / gi.cells();
}

}  // namespace mcslam
