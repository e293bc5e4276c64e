// "indoor": four furnished rooms at the corners of a 32 x 24 m block, joined by 2.6 m wide corridors into a
// ring. The ground loop (about 75 m) runs through all of them, turning in each room.
#include <cmath>

#include "world_layout.hpp"
#include "world_named.hpp"

namespace mcslam::sim {

namespace {

using kit::Opening;
using layout::Room;
using layout::RoomWall;

constexpr double kHeight = 2.8;
constexpr double kCorridorHalf = 1.3;

Material paint(Rng& rng) { return Material::texture(TextureKind::Plaster, rng.uniform(0.75, 1.05), 0.002); }

// A corridor between two rooms: the two long walls only (its ends open into the rooms), floor, ceiling, lights.
Room corridor(WorldBuilder& b, Rng& rng, const Vec2& lo, const Vec2& hi, bool along_x, const Material& wall,
              const Material& floor) {
  Room r;
  r.lo = lo;
  r.hi = hi;
  r.height = kHeight;
  RoomWall w1, w2;
  w1.wall.height = w2.wall.height = kHeight;
  if (along_x) {  // interior on the left of each wall
    w1.wall.a = lo;
    w1.wall.b = Vec2(hi.x(), lo.y());
    w2.wall.a = hi;
    w2.wall.b = Vec2(lo.x(), hi.y());
  } else {
    w1.wall.a = Vec2(hi.x(), lo.y());
    w1.wall.b = hi;
    w2.wall.a = Vec2(lo.x(), hi.y());
    w2.wall.b = lo;
  }
  r.walls = {w1, w2};
  for (const RoomWall& rw : r.walls) kit::addWall(b, rw.wall, wall, Material::unseen());
  kit::addFloor(b, lo, hi, floor);
  kit::addCeiling(b, lo, hi, kHeight, Material::texture(TextureKind::CeilingTiles, 1.0, 0.0023));
  const double len = along_x ? hi.x() - lo.x() : hi.y() - lo.y();
  for (double s = 1.8; s < len - 1.0; s += 3.5) {
    kit::addCeilingLight(
        b, along_x ? Vec2(lo.x() + s, 0.5 * (lo.y() + hi.y())) : Vec2(0.5 * (lo.x() + hi.x()), lo.y() + s), kHeight,
        5.0);
  }
  (void)rng;
  return r;
}

void furnishOffice(WorldBuilder& b, Room& room, Rng& rng, const layout::KeepOut& keep) {
  layout::fillWallSlots(room, rng, keep, 1.4, 1.5, 0.8, 0.8, [&](const Vec2& c, double yaw) {
    kit::addDesk(b, rng, c, yaw + M_PI);  // desks face the wall, chairs on the room side
  });
  layout::fillWallSlots(room, rng, keep, 0.9, 0.45, 0.3, 0.9, [&](const Vec2& c, double yaw) {
    if (rng.chance(0.5))
      kit::addBookshelf(b, rng, c, yaw, 0.9, rng.uniform(1.6, 2.1));
    else
      kit::addCabinet(b, rng, c, yaw, 0.9, 0.45, rng.uniform(0.75, 1.3));
  });
}

void furnishStorage(WorldBuilder& b, Room& room, Rng& rng, const layout::KeepOut& keep) {
  layout::fillWallSlots(room, rng, keep, 1.0, 0.4, 0.2, 0.9, [&](const Vec2& c, double yaw) {
    kit::addBookshelf(b, rng, c, yaw, 1.0, rng.uniform(1.8, 2.2));
  });
  layout::fillWallSlots(room, rng, keep, 0.6, 0.6, 0.4, 0.8,
                        [&](const Vec2& c, double yaw) { kit::addCrates(b, rng, c, yaw); });
  for (int tries = 0; tries < 30; ++tries) {  // a work bench in a free spot
    const Vec2 c(rng.uniform(room.lo.x() + 1.5, room.hi.x() - 1.5), rng.uniform(room.lo.y() + 1.5, room.hi.y() - 1.5));
    if (keep.clear(c, Vec2(1.0, 0.5), room.lo, room.hi)) {
      kit::addTable(b, rng, c, 0.0, 1.8, 0.8, 0.9);
      kit::addCrates(b, rng, c + Vec2(0.4, 0.0), 0.0);
      break;
    }
  }
}

void furnishLounge(WorldBuilder& b, Room& room, Rng& rng, const layout::KeepOut& keep) {
  layout::fillWallSlots(room, rng, keep, 2.0, 0.9, 0.8, 0.9,
                        [&](const Vec2& c, double yaw) { kit::addSofa(b, rng, c, yaw, 1.9); });
  layout::fillWallSlots(room, rng, keep, 0.8, 0.8, 0.5, 0.9, [&](const Vec2& c, double yaw) {
    if (rng.chance(0.6))
      kit::addPlant(b, rng, c, rng.uniform(1.0, 1.8));
    else
      kit::addBookshelf(b, rng, c, yaw, 0.8, 1.2);
  });
  for (int n = 0, tries = 0; tries < 40 && n < 2; ++tries) {  // low tables in free spots
    const Vec2 c(rng.uniform(room.lo.x() + 1.2, room.hi.x() - 1.2), rng.uniform(room.lo.y() + 1.2, room.hi.y() - 1.2));
    if (keep.clear(c, Vec2(0.6, 0.4), room.lo, room.hi)) {
      kit::addTable(b, rng, c, 0.0, 1.1, 0.7, 0.45);
      ++n;
    }
  }
}

void furnishMeeting(WorldBuilder& b, Room& room, Rng& rng, const layout::KeepOut& keep) {
  for (int tries = 0; tries < 60; ++tries) {  // a meeting table with chairs round it
    const Vec2 c(rng.uniform(room.lo.x() + 2.0, room.hi.x() - 2.0), rng.uniform(room.lo.y() + 1.8, room.hi.y() - 1.8));
    if (keep.clear(c, Vec2(1.7, 1.2), room.lo, room.hi)) {
      kit::addTable(b, rng, c, 0.0, 2.4, 1.1);
      for (int i = -1; i <= 1; ++i) {
        kit::addChair(b, rng, c + Vec2(0.7 * i, 0.85), -M_PI / 2);
        kit::addChair(b, rng, c + Vec2(0.7 * i, -0.85), M_PI / 2);
      }
      break;
    }
  }
  layout::fillWallSlots(room, rng, keep, 0.8, 0.5, 1.0, 0.8, [&](const Vec2& c, double yaw) {
    if (rng.chance(0.5))
      kit::addCabinet(b, rng, c, yaw, 0.8, 0.5, 0.9);
    else
      kit::addPlant(b, rng, c, 1.4);
  });
}

void decorateCorridor(WorldBuilder& b, Room& corr, Rng& rng) {
  for (RoomWall& rw : corr.walls) {
    const double len = rw.wall.length();
    kit::addSkirting(b, rw.wall, true, 0.0, len);
    for (double s = rng.uniform(1.0, 2.5); s < len - 1.5; s += rng.uniform(2.5, 4.5)) {
      const int kind = rng.integer(0, 3);
      if (kind == 0)
        kit::addDoor(b, rw.wall, true, s, 0.9);
      else if (kind == 1)
        kit::addPoster(b, rw.wall, true, s, 1.5, 0.6, 0.85);
      else if (kind == 2)
        kit::addNoticeBoard(b, rw.wall, true, s, 1.45, 1.2, 0.7);
      else
        kit::addRadiator(b, rw.wall, true, s, 1.0);
    }
  }
}

}  // namespace

std::shared_ptr<const World> buildIndoorWorld(const WorldOptions& options) {
  WorldBuilder b(options.seed, "indoor", options.textures_dir);
  Rng rng(hashOf(options.seed, 0x1d00));

  // The loop: room centres (4.5, 4), (27.5, 4), (27.5, 20), (4.5, 20); corridors run along its sides.
  RouteSpec route;
  route.corners = {Vec2(4.5, 4.0), Vec2(27.5, 4.0), Vec2(27.5, 20.0), Vec2(4.5, 20.0)};
  route.radii = {1.4, 1.2, 1.6, 1.3};
  route.stops = {1, 3};
  route.clearance = 0.45;
  const RouteCurve curve(route);

  // Rooms: A (south-west), B (south-east), C (north-east), D (north-west). Walls S, E, N, W.
  Room A = layout::makeRoom(Vec2(0, 0), Vec2(9, 8), kHeight, {true, false, false, true});
  Room B = layout::makeRoom(Vec2(23, 0), Vec2(32, 8), kHeight, {true, true, false, false});
  Room C = layout::makeRoom(Vec2(23, 16), Vec2(32, 24), kHeight, {false, true, true, false});
  Room D = layout::makeRoom(Vec2(0, 16), Vec2(9, 24), kHeight, {false, false, true, true});
  const double c0 = 4.0 - kCorridorHalf, c1 = 4.0 + kCorridorHalf;  // corridor S/N across y, E/W across x
  auto opening = [](double from, double to) { return Opening{from, to, 0.0, 2.4}; };
  A.walls[1].openings.push_back(opening(c0, c1));                // east -> corridor S
  A.walls[2].openings.push_back(opening(9 - 5.8, 9 - 3.2));      // north -> corridor W
  B.walls[3].openings.push_back(opening(8 - c1, 8 - c0));        // west -> corridor S
  B.walls[2].openings.push_back(opening(32 - 28.8, 32 - 26.2));  // north -> corridor E
  C.walls[0].openings.push_back(opening(26.2 - 23, 28.8 - 23));  // south -> corridor E
  C.walls[3].openings.push_back(opening(24 - 21.3, 24 - 18.7));  // west -> corridor N
  D.walls[1].openings.push_back(opening(18.7 - 16, 21.3 - 16));  // east -> corridor N
  D.walls[0].openings.push_back(opening(3.2, 5.8));              // south -> corridor W

  const Material outside = Material::unseen();
  const Material ceiling = Material::texture(TextureKind::CeilingTiles, 1.0, 0.0023);
  layout::buildRoom(b, A, paint(rng), outside, Material::texture(TextureKind::Carpet, 1.0, 0.002), ceiling, 3.5, 6.0);
  layout::buildRoom(b, B, Material::texture(TextureKind::Brick, 1.0, 0.0022), outside,
                    Material::texture(TextureKind::Tiles, 1.0, 0.002), ceiling, 3.5, 6.0);
  layout::buildRoom(b, C, paint(rng), outside, Material::texture(TextureKind::WoodPlanks, 1.0, 0.0022), ceiling, 3.5,
                    6.0);
  layout::buildRoom(b, D, Material::texture(TextureKind::Concrete, 1.1, 0.002), outside,
                    Material::texture(TextureKind::Carpet, 0.8, 0.002), ceiling, 3.5, 6.0);

  Room S = corridor(b, rng, Vec2(9, c0), Vec2(23, c1), true, paint(rng),
                    Material::texture(TextureKind::Linoleum, 1.0, 0.002));
  Room N = corridor(b, rng, Vec2(9, 20 - kCorridorHalf), Vec2(23, 20 + kCorridorHalf), true, paint(rng),
                    Material::texture(TextureKind::Tiles, 0.9, 0.002));
  Room E = corridor(b, rng, Vec2(27.5 - kCorridorHalf, 8), Vec2(27.5 + kCorridorHalf, 16), false,
                    Material::texture(TextureKind::Concrete, 1.0, 0.002),
                    Material::texture(TextureKind::Linoleum, 1.0, 0.002));
  Room W = corridor(b, rng, Vec2(4.5 - kCorridorHalf, 8), Vec2(4.5 + kCorridorHalf, 16), false, paint(rng),
                    Material::texture(TextureKind::Linoleum, 0.8, 0.002));

  // Lanes people walk along (1.6 m or more from the route), kept free of furniture.
  layout::KeepOut keep;
  keep.route = &curve;
  keep.lanes = {{Vec2(1.0, 1.6), Vec2(8.0, 1.6)},
                {Vec2(30.4, 1.0), Vec2(30.4, 7.0)},
                {Vec2(24.0, 22.4), Vec2(31.0, 22.4)},
                {Vec2(1.6, 17.0), Vec2(1.6, 23.0)}};
  furnishOffice(b, A, rng, keep);
  furnishStorage(b, B, rng, keep);
  furnishLounge(b, C, rng, keep);
  furnishMeeting(b, D, rng, keep);
  for (Room* r : {&A, &B, &C, &D}) layout::decorateWalls(b, *r, rng, 3);
  for (Room* r : {&S, &N, &E}) decorateCorridor(b, *r, rng);
  // Corridor W is left bare: a poorly textured stretch.
  for (RoomWall& rw : W.walls) kit::addSkirting(b, rw.wall, true, 0.0, rw.wall.length());

  if (options.moving_objects) {
    // People walking the lanes, back and forth.
    const double speeds[] = {1.2, 1.1, 1.3, 1.15}, phases[] = {0.0, 1.7, 3.1, 0.9};
    for (std::size_t i = 0; i < keep.lanes.size(); ++i) {
      Walker w;
      w.a = keep.lanes[i].first;
      w.b = keep.lanes[i].second;
      w.speed = speeds[i];
      w.phase = phases[i];
      b.addWalker(w);
    }
  }

  b.setAmbient(0.22, 0.05, 1.2);
  b.setExposure(0.55);
  b.setRoute(route);
  return b.build();
}

}  // namespace mcslam::sim
