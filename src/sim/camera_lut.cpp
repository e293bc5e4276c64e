#include "camera_lut.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <mutex>
#include <tuple>

#include "mcslam/core/worker_pool.hpp"

namespace mcslam::sim {

namespace {

using Key = std::tuple<int, int, double, double, double, double, int, std::array<double, 4>, int>;

// The bearings of every pixel centre, row-major, and whether the model has one.
struct PixelBearings {
  int W = 0, H = 0;
  std::vector<Vec3> bearing;
  std::vector<uint8_t> ok;
  std::size_t at(int x, int y) const { return static_cast<std::size_t>(y) * W + x; }
};

void unprojectPixels(const CameraModel& m, WorkerPool& pool, PixelBearings& px) {
  const int W = m.width(), H = m.height();
  px.W = W;
  px.H = H;
  px.bearing.assign(static_cast<std::size_t>(W) * H, Vec3::Zero());
  px.ok.assign(static_cast<std::size_t>(W) * H, 0);
  std::vector<Vec3>& bearing = px.bearing;
  std::vector<uint8_t>& ok = px.ok;
  pool.forEach(H, [&](int y) {
    for (int x = 0; x < W; ++x) {
      Vec3 b;
      const std::size_t i = static_cast<std::size_t>(y) * W + x;
      if (m.unproject(Vec2(x, y), b)) {
        bearing[i] = b;
        ok[i] = 1;
      }
    }
  });
}

// The rays of the table: bearing and angular pixel size from the neighbours (one-sided at the borders).
void fillRays(const PixelBearings& px, WorkerPool& pool, CameraLut& lut) {
  const int W = px.W, H = px.H;
  const std::vector<Vec3>& bearing = px.bearing;
  const std::vector<uint8_t>& ok = px.ok;
  pool.forEach(H, [&](int y) {
    for (int x = 0; x < W; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * W + x;
      if (!ok[i]) continue;
      auto step = [&](int dx, int dy) {
        const int xa = std::clamp(x - dx, 0, W - 1), ya = std::clamp(y - dy, 0, H - 1);
        const int xb = std::clamp(x + dx, 0, W - 1), yb = std::clamp(y + dy, 0, H - 1);
        const std::size_t a = static_cast<std::size_t>(ya) * W + xa, b = static_cast<std::size_t>(yb) * W + xb;
        const int span = (xb - xa) + (yb - ya);
        if (span == 0) return 0.0;
        if (ok[a] && ok[b]) return (bearing[b] - bearing[a]).norm() / span;
        if (ok[b]) return (bearing[b] - bearing[i]).norm() / std::max(1, (xb - x) + (yb - y));
        if (ok[a]) return (bearing[i] - bearing[a]).norm() / std::max(1, (x - xa) + (y - ya));
        return 0.0;
      };
      const double sx = step(1, 0), sy = step(0, 1);
      const double size = std::sqrt(std::max(sx, 1e-9) * std::max(sy, 1e-9));
      float* r = lut.ray(x, y);
      for (int k = 0; k < 3; ++k) r[k] = static_cast<float>(bearing[i][k]);
      r[3] = static_cast<float>(std::max(size, 1e-7));
    }
  });
}

// Pixels [x0, x1) x [y0, y1) of one tile.
struct TileRect {
  int x0, y0, x1, y1;
};

// Bounds of the tile's rays on the tangent plane of the cone's axis, along the tile's image x and y directions,
// as four planes through the camera centre.
void tilePlanes(const PixelBearings& px, const TileRect& r, const Vec3& axis, double max_angle, double margin,
                CameraLut::Tile& t) {
  const int W = px.W;
  const std::vector<Vec3>& bearing = px.bearing;
  const Vec3 across = bearing[static_cast<std::size_t>((r.y0 + r.y1 - 1) / 2) * W + r.x1 - 1] -
                      bearing[static_cast<std::size_t>((r.y0 + r.y1 - 1) / 2) * W + r.x0];
  Vec3 ex = across - across.dot(axis) * axis;
  if (ex.squaredNorm() < 1e-20) ex = axis.unitOrthogonal();
  ex.normalize();
  const Vec3 ey = axis.cross(ex);
  double lo_x = 1e9, hi_x = -1e9, lo_y = 1e9, hi_y = -1e9;
  for (int y = r.y0; y < r.y1; ++y) {
    for (int x = r.x0; x < r.x1; ++x) {
      const std::size_t i = px.at(x, y);
      if (!px.ok[i]) continue;
      const double z = bearing[i].dot(axis);
      const double a = bearing[i].dot(ex) / z, b = bearing[i].dot(ey) / z;
      lo_x = std::min(lo_x, a);
      hi_x = std::max(hi_x, a);
      lo_y = std::min(lo_y, b);
      hi_y = std::max(hi_y, b);
    }
  }
  const double m = margin / (std::cos(max_angle) * std::cos(max_angle));  // angle -> tangent-plane units
  const Vec3 planes[4] = {ex - (lo_x - m) * axis, (hi_x + m) * axis - ex, ey - (lo_y - m) * axis,
                          (hi_y + m) * axis - ey};
  for (int p = 0; p < 4; ++p) {
    for (int k = 0; k < 3; ++k) t.planes[p][k] = static_cast<float>(planes[p][k]);
  }
  t.has_planes = true;
}

// A tile's cone: mean direction, widest ray, plus a pixel of margin for sub-pixel samples; and its planes.
void boundTile(const PixelBearings& px, const CameraLut& lut, const TileRect& r, CameraLut::Tile& t) {
  const std::vector<Vec3>& bearing = px.bearing;
  Vec3 sum = Vec3::Zero();
  double max_size = 0;
  for (int y = r.y0; y < r.y1; ++y) {
    for (int x = r.x0; x < r.x1; ++x) {
      const std::size_t i = px.at(x, y);
      if (!px.ok[i]) continue;
      sum += bearing[i];
      max_size = std::max(max_size, static_cast<double>(lut.ray(x, y)[3]));
    }
  }
  if (sum.squaredNorm() == 0) return;
  const Vec3 axis = sum.normalized();
  double max_angle = 0;
  for (int y = r.y0; y < r.y1; ++y) {
    for (int x = r.x0; x < r.x1; ++x) {
      const std::size_t i = px.at(x, y);
      if (px.ok[i]) max_angle = std::max(max_angle, std::acos(std::clamp(axis.dot(bearing[i]), -1.0, 1.0)));
    }
  }
  const double margin = 1.5 * max_size + 1e-4;  // sub-pixel samples reach half a pixel (and a bit) out
  max_angle = std::min(M_PI, max_angle + margin);
  for (int k = 0; k < 3; ++k) t.axis[k] = static_cast<float>(axis[k]);
  t.cos_a = static_cast<float>(std::cos(max_angle));
  t.sin_a = static_cast<float>(std::sin(max_angle));
  t.any_valid = true;
  if (max_angle > 1.2) return;  // too wide for tangent-plane bounds: the cone alone culls
  tilePlanes(px, r, axis, max_angle, margin, t);
}

std::shared_ptr<const CameraLut> compute(const CameraModel& m, int tile, WorkerPool& pool) {
  auto lut = std::make_shared<CameraLut>();
  const int W = m.width(), H = m.height();
  lut->layout(W, H, tile);
  PixelBearings px;
  unprojectPixels(m, pool, px);
  fillRays(px, pool, *lut);
  lut->tiles.resize(static_cast<std::size_t>(lut->tiles_x) * lut->tiles_y);
  for (int ty = 0; ty < lut->tiles_y; ++ty) {
    for (int tx = 0; tx < lut->tiles_x; ++tx) {
      const TileRect r{tx * tile, ty * tile, std::min(W, (tx + 1) * tile), std::min(H, (ty + 1) * tile)};
      boundTile(px, *lut, r, lut->tiles[static_cast<std::size_t>(ty) * lut->tiles_x + tx]);
    }
  }
  return lut;
}

}  // namespace

void CameraLut::layout(int w, int h, int tile_size) {
  width = w;
  height = h;
  tile = tile_size;
  tiles_x = (w + tile - 1) / tile;
  tiles_y = (h + tile - 1) / tile;
  const uint32_t ts = static_cast<uint32_t>(tile);
  rays.assign(static_cast<std::size_t>(tiles_x) * tiles_y * ts * ts * 4, 0.f);
  row_start_.resize(h);
  for (int y = 0; y < h; ++y) row_start_[y] = (y / ts * tiles_x * ts + y % ts) * ts;
  col_offset_.resize(w);
  for (int x = 0; x < w; ++x) col_offset_[x] = x / ts * ts * ts + x % ts;
}

std::shared_ptr<const CameraLut> CameraLut::get(const CameraModel& m, int tile, WorkerPool& pool) {
  static std::mutex mutex;
  static std::map<Key, std::weak_ptr<const CameraLut>> cache;
  const Key key{m.width(),  m.height(), m.fx(), m.fy(), m.cx(), m.cy(), static_cast<int>(m.distortion()),
                m.coeffs(), tile};
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (auto it = cache.find(key); it != cache.end()) {
      if (auto lut = it->second.lock()) return lut;
    }
  }
  auto lut = compute(m, tile, pool);
  std::lock_guard<std::mutex> lock(mutex);
  cache[key] = lut;
  return lut;
}

}  // namespace mcslam::sim
