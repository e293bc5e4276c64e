// "corridor": a 45 m long, 2.4 m wide corridor between two 8 x 8 m halls. Stretches of it are bare (plain paint
// above plain lino: little to track), others have doors, posters and notice boards. The loop goes down the
// right-hand side, turns round in the far hall and comes back on the other side (about 105 m).
#include <cmath>

#include "world_layout.hpp"
#include "world_named.hpp"

namespace mcslam::sim {

namespace {

using layout::Room;
using layout::RoomWall;

constexpr double kLength = 45.0, kHalfWidth = 1.2, kHeight = 2.6, kHallHeight = 3.2;

// Which stretches of the corridor are bare (from, to along x).
constexpr double kBare[][2] = {{9.0, 19.0}, {29.0, 37.0}};

bool inBare(double x0, double x1) {
  for (const auto& r : kBare) {
    if (x1 > r[0] && x0 < r[1]) return true;
  }
  return false;
}

void furnishHall(WorldBuilder& b, Room& hall, Rng& rng, const layout::KeepOut& keep) {
  layout::fillWallSlots(hall, rng, keep, 1.6, 0.6, 1.2, 0.8, [&](const Vec2& c, double yaw) {
    const int kind = rng.integer(0, 3);
    if (kind == 0)
      kit::addSofa(b, rng, c, yaw, 1.6);
    else if (kind == 1)
      kit::addCabinet(b, rng, c, yaw, 1.2, 0.6, 1.8);  // vending machine / locker
    else if (kind == 2)
      kit::addPlant(b, rng, c, rng.uniform(1.2, 1.9));
    else
      kit::addBookshelf(b, rng, c, yaw, 1.2, 1.9);
  });
  layout::decorateWalls(b, hall, rng, 3);
}

}  // namespace

std::shared_ptr<const World> buildCorridorWorld(const WorldOptions& options) {
  WorldBuilder b(options.seed, "corridor", options.textures_dir);
  Rng rng(hashOf(options.seed, 0xc044));

  RouteSpec route;
  route.corners = {Vec2(-4.0, -2.0),          Vec2(-0.8, -0.4),         Vec2(kLength + 0.8, -0.4),
                   Vec2(kLength + 4.0, -2.0), Vec2(kLength + 4.0, 2.0), Vec2(kLength + 0.8, 0.4),
                   Vec2(-0.8, 0.4),           Vec2(-4.0, 2.0)};
  route.radii = {1.0, 2.0, 2.0, 1.0, 1.0, 2.0, 2.0, 1.0};
  route.stops = {3};
  route.clearance = 0.45;
  const RouteCurve curve(route);

  // Halls.
  Room start = layout::makeRoom(Vec2(-8, -4), Vec2(0, 4), kHallHeight, {true, false, true, true});
  Room end = layout::makeRoom(Vec2(kLength, -4), Vec2(kLength + 8, 4), kHallHeight, {true, true, true, false});
  start.walls[1].openings.push_back({4 - kHalfWidth, 4 + kHalfWidth, 0.0, kHeight});
  end.walls[3].openings.push_back({4 - kHalfWidth, 4 + kHalfWidth, 0.0, kHeight});
  const Material ceiling = Material::texture(TextureKind::CeilingTiles, 1.0, 0.0023);
  layout::buildRoom(b, start, Material::texture(TextureKind::Brick, 1.0, 0.0022), Material::unseen(),
                    Material::texture(TextureKind::Tiles, 1.0, 0.002), ceiling, 3.0, 7.0);
  layout::buildRoom(b, end, Material::texture(TextureKind::Concrete, 1.0, 0.002), Material::unseen(),
                    Material::texture(TextureKind::Tiles, 0.85, 0.002), ceiling, 3.0, 7.0);

  // The corridor: two long walls, plain lino, lights every 3 m.
  const Material wall_paint = Material::texture(TextureKind::Plaster, 1.0, 0.002);
  kit::Wall south{Vec2(0, -kHalfWidth), Vec2(kLength, -kHalfWidth), kHeight, 0.15};
  kit::Wall north{Vec2(kLength, kHalfWidth), Vec2(0, kHalfWidth), kHeight, 0.15};
  kit::addWall(b, south, wall_paint, Material::unseen());
  kit::addWall(b, north, wall_paint, Material::unseen());
  kit::addFloor(b, Vec2(0, -kHalfWidth), Vec2(kLength, kHalfWidth),
                Material::texture(TextureKind::Linoleum, 1.0, 0.002));
  kit::addCeiling(b, Vec2(0, -kHalfWidth), Vec2(kLength, kHalfWidth), kHeight, ceiling);
  for (double x = 1.5; x < kLength; x += 3.0) kit::addCeilingLight(b, Vec2(x, 0.0), kHeight, 4.5);
  // Decorations outside the bare stretches; skirting everywhere.
  for (const kit::Wall* w : {&south, &north}) {
    kit::addSkirting(b, *w, true, 0.0, kLength);
    for (double s = rng.uniform(1.0, 2.0); s < kLength - 1.0; s += rng.uniform(2.2, 4.0)) {
      const double x = w == &south ? s : kLength - s;
      if (inBare(x - 1.0, x + 1.0)) continue;
      const int kind = rng.integer(0, 4);
      if (kind <= 1)
        kit::addDoor(b, *w, true, s, 0.9);
      else if (kind == 2)
        kit::addPoster(b, *w, true, s, 1.5, 0.6, 0.85);
      else if (kind == 3)
        kit::addNoticeBoard(b, *w, true, s, 1.45, 1.3, 0.8);
      else
        kit::addRadiator(b, *w, true, s, 1.0);
    }
  }

  layout::KeepOut keep;
  keep.route = &curve;
  keep.lanes = {{Vec2(-7.0, -3.2), Vec2(-7.0, 3.2)}, {Vec2(kLength + 1.0, 3.3), Vec2(kLength + 7.0, 3.3)}};
  furnishHall(b, start, rng, keep);
  furnishHall(b, end, rng, keep);

  if (options.moving_objects) {
    for (std::size_t i = 0; i < keep.lanes.size(); ++i) {
      Walker w;
      w.a = keep.lanes[i].first;
      w.b = keep.lanes[i].second;
      w.speed = 1.1 + 0.1 * static_cast<double>(i);
      w.phase = 1.3 * static_cast<double>(i);
      b.addWalker(w);
    }
  }

  b.setAmbient(0.2, 0.05, 1.2);
  b.setExposure(0.55);
  b.setRoute(route);
  return b.build();
}

}  // namespace mcslam::sim
