#pragma once
// Per-camera ray table: the unit bearing of every pixel centre (from CameraModel::unproject, so distortion is
// exact per pixel, fisheyes beyond 90 degrees included), its angular size, and a bounding cone per tile.
// Tables are shared between renderers of the same camera model.
#include <cstdint>
#include <memory>
#include <vector>

#include "mcslam/calib/camera_model.hpp"

namespace mcslam {
class WorkerPool;
}

namespace mcslam::sim {

struct CameraLut {
  struct Tile {
    float axis[3] = {0, 0, 1};   // camera frame
    float cos_a = 1, sin_a = 0;  // half-angle of the cone holding every ray of the tile (with a pixel's margin)
    bool any_valid = false;
    // Four planes through the camera centre bounding the tile's rays more tightly than the cone: every ray b
    // of the tile has planes[i] . b >= 0. Not set (has_planes false) for tiles reaching 90 degrees off their axis.
    bool has_planes = false;
    float planes[4][3] = {};
  };
  int width = 0, height = 0, tile = 16, tiles_x = 0, tiles_y = 0;
  // 4 floats per pixel: bearing x, y, z and angular size (radians; 0 = invalid pixel), stored tile by tile (each
  // tile's rays row-major in one block, partial tiles padded): the renderer walks the image tile by tile, and in
  // a row-major table every row of a tile would be a separate stream from memory, which the prefetcher does not
  // follow.
  std::vector<float> rays;
  std::vector<Tile> tiles;

  // Pixels x, x + 1, ... up to the end of x's tile row follow each other.
  const float* ray(int x, int y) const { return &rays[index(x, y)]; }
  float* ray(int x, int y) { return &rays[index(x, y)]; }
  bool valid(int x, int y) const { return ray(x, y)[3] > 0.f; }
  // Sets the sizes and the tile layout (before the rays are filled in).
  void layout(int w, int h, int tile_size);

  static std::shared_ptr<const CameraLut> get(const CameraModel& model, int tile, WorkerPool& pool);

 private:
  std::size_t index(int x, int y) const { return 4 * (static_cast<std::size_t>(row_start_[y]) + col_offset_[x]); }
  std::vector<uint32_t> row_start_;   // per image row: index of its first pixel's ray in its tile row
  std::vector<uint32_t> col_offset_;  // per image column: offset from there
};

}  // namespace mcslam::sim
