#pragma once
// Overlap between the cameras of a rig (paper section IV-A, eq. 1-2), computed once at start.
//
// Each image is divided into a grid of cells. For every ordered camera pair (i, j) and every cell of
// camera i, the map lists the cells of camera j that the epipolar curves of the cell's pixels cross,
// for scene depths in a configured range. Working with the full camera models (distortion included,
// fisheyes beyond 90 degrees) and a depth range instead of the paper's pinhole F matrix at one depth
// keeps it right for any lens and any rig orientation. A pair with no cell is non-overlapping.
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "mcslam/calib/rig.hpp"

namespace mcslam {

struct OverlapOptions {
  int cell_size_px = 32;     // grid cell edge, pixels
  double min_depth = 0.3;    // metres: the nearest scene point a match may have
  double max_depth = 100.0;  // metres: the farthest (use a large value outdoors)
  int depth_samples = 48;    // samples along each ray, uniform in inverse depth
  int samples_per_cell = 3;  // per cell edge: 3 -> 3x3 pixels per cell (corners, edges, centre)
  int dilate_cells = 1;      // grow each candidate set by this many cells (keypoint and calibration error)
};

// A grid of square cells over one image.
struct CellGrid {
  int cols = 0, rows = 0, cell_size = 1, width = 0, height = 0;

  CellGrid() = default;
  CellGrid(int image_width, int image_height, int cell_size_px);
  int cells() const { return cols * rows; }
  // Cell of a pixel; -1 outside the image.
  int cellOf(double x, double y) const {
    if (!(x >= -0.5 && y >= -0.5 && x < width - 0.5 && y < height - 0.5)) return -1;
    const int cx = std::min(cols - 1, static_cast<int>((x + 0.5) / cell_size));
    const int cy = std::min(rows - 1, static_cast<int>((y + 0.5) / cell_size));
    return cy * cols + cx;
  }
};

class OverlapMap {
 public:
  OverlapMap() = default;
  OverlapMap(const Rig& rig, const OverlapOptions& options);

  int cameras() const { return cameras_; }
  const OverlapOptions& options() const { return options_; }
  const CellGrid& grid(int cam) const { return grids_[cam]; }

  // Cells of camera j where a feature of cell `cell_i` of camera i may have its match.
  std::span<const int32_t> candidates(int i, int j, int cell_i) const {
    const Pair& p = pairs_[i * cameras_ + j];
    if (p.offsets.empty()) return {};
    return {p.cells.data() + p.offsets[cell_i], p.cells.data() + p.offsets[cell_i + 1]};
  }
  bool overlaps(int i, int j) const { return i != j && !pairs_[i * cameras_ + j].cells.empty(); }
  // Share of camera i's cells that have at least one candidate cell in camera j.
  double overlapFraction(int i, int j) const { return pairs_[i * cameras_ + j].fraction; }
  // Unordered pairs (i < j) that overlap either way.
  const std::vector<std::pair<int, int>>& overlappingPairs() const { return overlapping_pairs_; }

 private:
  struct Pair {
    std::vector<int32_t> offsets;  // cells(i) + 1 entries (empty when no overlap)
    std::vector<int32_t> cells;
    double fraction = 0;
  };
  void computePair(const Rig& rig, int i, int j);

  int cameras_ = 0;
  OverlapOptions options_;
  std::vector<CellGrid> grids_;
  std::vector<Pair> pairs_;  // row-major [i][j]
  std::vector<std::pair<int, int>> overlapping_pairs_;
};

}  // namespace mcslam
