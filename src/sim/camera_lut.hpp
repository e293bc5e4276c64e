#pragma once
// Per-camera ray table: the unit bearing of every pixel centre (from CameraModel::unproject, so distortion is
// exact per pixel, fisheyes beyond 90 degrees included), its angular size, and a bounding cone per tile.
// Tables are shared between renderers of the same camera model.
#include <memory>
#include <vector>

#include "mcslam/calib/camera_model.hpp"

namespace mcslam::sim {

class ThreadPool;

struct CameraLut {
  struct Tile {
    float axis[3] = {0, 0, 1};  // camera frame
    float cos_a = 1, sin_a = 0;   // half-angle of the cone holding every ray of the tile (with a pixel's margin)
    bool any_valid = false;
    // Four planes through the camera centre bounding the tile's rays more tightly than the cone: every ray b
    // of the tile has planes[i] . b >= 0. Not set (has_planes false) for tiles reaching 90 degrees off their axis.
    bool has_planes = false;
    float planes[4][3] = {};
  };
  int width = 0, height = 0, tile = 16, tiles_x = 0, tiles_y = 0;
  std::vector<float> rays;  // 4 floats per pixel: bearing x, y, z and angular size (radians; 0 = invalid pixel)
  std::vector<Tile> tiles;

  const float* ray(int x, int y) const { return &rays[4 * (static_cast<std::size_t>(y) * width + x)]; }
  bool valid(int x, int y) const { return ray(x, y)[3] > 0.f; }

  static std::shared_ptr<const CameraLut> get(const CameraModel& model, int tile, ThreadPool& pool);
};

}  // namespace mcslam::sim
