#include "world_layout.hpp"

#include <algorithm>
#include <cmath>

namespace mcslam::sim::layout {

bool RoomWall::isFree(double from, double to) const {
  if (from < 0.1 || to > wall.length() - 0.1) return false;
  for (const kit::Opening& o : openings) {
    if (to > o.from - 0.15 && from < o.to + 0.15) return false;
  }
  for (const auto& [a, b] : used) {
    if (to > a - 0.1 && from < b + 0.1) return false;
  }
  return true;
}

Room makeRoom(const Vec2& lo, const Vec2& hi, double height, const std::array<bool, 4>& exterior) {
  Room r;
  r.lo = lo;
  r.hi = hi;
  r.height = height;
  const Vec2 corners[4] = {lo, Vec2(hi.x(), lo.y()), hi, Vec2(lo.x(), hi.y())};
  for (int i = 0; i < 4; ++i) {
    RoomWall w;
    w.wall.a = corners[i];
    w.wall.b = corners[(i + 1) % 4];
    w.wall.height = height;
    w.exterior = exterior[i];
    r.walls.push_back(w);
  }
  return r;
}

namespace {
double boxDistance(const Vec2& p, const Vec2& c, const Vec2& half) {
  const Vec2 d = (p - c).cwiseAbs() - half;
  return Vec2(std::max(d.x(), 0.0), std::max(d.y(), 0.0)).norm();
}
}  // namespace

bool KeepOut::clear(const Vec2& c, const Vec2& half, const Vec2& lo, const Vec2& hi) const {
  if (c.x() - half.x() < lo.x() || c.y() - half.y() < lo.y() || c.x() + half.x() > hi.x() ||
      c.y() + half.y() > hi.y()) {
    return false;
  }
  if (route) {
    for (const Vec2& p : route->points()) {
      if (boxDistance(p, c, half) < route_margin) return false;
    }
  }
  for (const auto& [a, b] : lanes) {
    const double len = (b - a).norm();
    for (double s = 0; s <= len; s += 0.1) {
      if (boxDistance(a + (b - a) * (s / std::max(len, 1e-9)), c, half) < lane_margin) return false;
    }
  }
  return true;
}

int fillWallSlots(Room& room, Rng& rng, const KeepOut& keep_out, double width, double depth, double spacing,
                  double keep_probability, const std::function<void(const Vec2& centre, double yaw)>& place) {
  int placed = 0;
  for (RoomWall& rw : room.walls) {
    const kit::Wall& w = rw.wall;
    const Vec2 n = w.leftNormal();  // into the room
    const double yaw = std::atan2(n.y(), n.x());
    for (double along = 0.3 + 0.5 * width + rng.uniform(0, 0.6); along + 0.5 * width < w.length() - 0.3;
         along += width + spacing * rng.uniform(0.6, 1.4)) {
      if (!rng.chance(keep_probability)) continue;
      if (!rw.isFree(along - 0.5 * width, along + 0.5 * width)) continue;
      const Vec2 c = w.a + w.dir() * along + n * (0.5 * w.thickness + 0.5 * depth + 0.03);
      const Vec2 half = kit::turnedHalf(yaw, depth, width);
      if (!keep_out.clear(c, half, room.lo, room.hi)) continue;
      place(c, yaw);
      rw.take(along - 0.5 * width, along + 0.5 * width);
      ++placed;
    }
  }
  return placed;
}

void decorateWalls(WorldBuilder& b, Room& room, Rng& rng, int items_per_wall) {
  for (RoomWall& rw : room.walls) {
    const kit::Wall& w = rw.wall;
    kit::addSkirting(b, w, true, 0.0, w.length());
    for (int item = 0; item < items_per_wall; ++item) {
      const int kind = rw.exterior ? rng.integer(0, 5) : rng.integer(0, 4);
      double width = 0, from = 0;
      switch (kind) {
        case 0: width = rng.uniform(0.45, 0.8); break;  // poster
        case 1: width = rng.uniform(1.0, 1.8); break;   // notice board
        case 2: width = rng.uniform(1.2, 2.2); break;   // whiteboard
        case 3: width = 1.0; break;                     // door (with frame)
        case 4: width = rng.uniform(0.45, 0.8); break;  // poster
        default: width = rng.uniform(1.0, 1.8); break;  // window
      }
      bool found = false;
      for (int tries = 0; tries < 12 && !found; ++tries) {
        from = rng.uniform(0.2, std::max(0.2, w.length() - width - 0.2));
        found = rw.isFree(from, from + width);
      }
      if (!found) continue;
      rw.take(from, from + width);
      const double mid = from + 0.5 * width;
      switch (kind) {
        case 0:
        case 4: kit::addPoster(b, w, true, mid, rng.uniform(1.3, 1.7), width, width * rng.uniform(1.2, 1.45)); break;
        case 1: kit::addNoticeBoard(b, w, true, mid, 1.45, width, width * 0.5); break;
        case 2: kit::addWhiteboard(b, w, true, mid, 1.45, width, width * 0.5); break;
        case 3: kit::addDoor(b, w, true, mid, 0.9); break;
        default:
          kit::addWindow(b, w, true, mid, width, 0.95, 2.15);
          kit::addRadiator(b, w, true, mid, std::min(width, 1.2));
          break;
      }
    }
  }
}

void buildRoom(WorldBuilder& b, Room& room, const Material& wall, const Material& outside, const Material& floor,
               const Material& ceiling, double light_spacing, double light_intensity) {
  for (const RoomWall& rw : room.walls) kit::addWall(b, rw.wall, wall, outside, rw.openings);
  kit::addFloor(b, room.lo, room.hi, floor);
  kit::addCeiling(b, room.lo, room.hi, room.height, ceiling);
  const Vec2 size = room.hi - room.lo;
  const int nx = std::max(1, static_cast<int>(std::round(size.x() / light_spacing)));
  const int ny = std::max(1, static_cast<int>(std::round(size.y() / light_spacing)));
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      const Vec2 at = room.lo + Vec2(size.x() * (i + 0.5) / nx, size.y() * (j + 0.5) / ny);
      kit::addCeilingLight(b, at, room.height, light_intensity);
    }
  }
}

}  // namespace mcslam::sim::layout
