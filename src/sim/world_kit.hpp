#pragma once
// Building blocks for the named worlds: walls with openings, floors and ceilings with lights, and furniture
// with plausible proportions and materials. Furniture helpers take a footprint centre and a yaw (multiples of
// 90 degrees keep boxes axis-aligned, which renders fastest); "front" is the local +x side.
#include <vector>

#include "hash.hpp"
#include "mcslam/sim/world.hpp"

namespace mcslam::sim::kit {

struct Opening {
  double from = 0, to = 1;       // metres along the wall from its start
  double bottom = 0, top = 2.1;  // doorway: 0..2.1; window: e.g. 0.9..2.0
};

// A straight wall from a to b (floor plan), `left` material on the side to the left of a->b.
struct Wall {
  Vec2 a, b;
  double height = 2.8, thickness = 0.15;
  Vec2 dir() const { return (b - a).normalized(); }
  Vec2 leftNormal() const { return Vec2(-dir().y(), dir().x()); }
  double length() const { return (b - a).norm(); }
  // Point on the wall's surface on one side, `along` metres from a, at height z, `out` metres off the surface.
  Vec3 surfacePoint(bool left_side, double along, double z, double out = 0.0) const;
};

void addWall(WorldBuilder& b, const Wall& w, const Material& left, const Material& right,
             const std::vector<Opening>& openings = {});

// Slab with its top at z = 0 (floor) or its bottom at z = height (ceiling).
void addFloor(WorldBuilder& b, const Vec2& lo, const Vec2& hi, const Material& m);
void addCeiling(WorldBuilder& b, const Vec2& lo, const Vec2& hi, double height, const Material& m);
// A ceiling panel lamp with its point light just below.
void addCeilingLight(WorldBuilder& b, const Vec2& at, double height, double intensity);

// Wall decorations: thin panels on one side of a wall, centred `along` metres from its start at height z.
void addPoster(WorldBuilder& b, const Wall& w, bool left_side, double along, double z, double width, double height);
void addNoticeBoard(WorldBuilder& b, const Wall& w, bool left_side, double along, double z, double width,
                    double height);
void addWhiteboard(WorldBuilder& b, const Wall& w, bool left_side, double along, double z, double width, double height);
// Closed door with frame (the wall behind it stays solid).
void addDoor(WorldBuilder& b, const Wall& w, bool left_side, double along, double width = 0.9);
void addRadiator(WorldBuilder& b, const Wall& w, bool left_side, double along, double width);
void addWindow(WorldBuilder& b, const Wall& w, bool left_side, double along, double width, double bottom, double top);
void addSkirting(WorldBuilder& b, const Wall& w, bool left_side, double from, double to);

// Furniture. c = footprint centre, yaw in radians.
void addTable(WorldBuilder& b, Rng& rng, const Vec2& c, double yaw, double length, double width, double height = 0.74);
void addDesk(WorldBuilder& b, Rng& rng, const Vec2& c, double yaw);  // desk with monitor, drawers, chair
void addCabinet(WorldBuilder& b, Rng& rng, const Vec2& c, double yaw, double width, double depth, double height);
void addBookshelf(WorldBuilder& b, Rng& rng, const Vec2& c, double yaw, double width, double height);
void addChair(WorldBuilder& b, Rng& rng, const Vec2& c, double yaw);
void addSofa(WorldBuilder& b, Rng& rng, const Vec2& c, double yaw, double length);
void addPlant(WorldBuilder& b, Rng& rng, const Vec2& c, double height);
void addBin(WorldBuilder& b, Rng& rng, const Vec2& c);
void addCrates(WorldBuilder& b, Rng& rng, const Vec2& c, double yaw);  // a stack of boxes
void addPillar(WorldBuilder& b, const Vec2& c, double radius, double height, const Material& m);

// Footprint half extents of a piece turned by yaw, for placement checks.
Vec2 turnedHalf(double yaw, double length, double width);

}  // namespace mcslam::sim::kit
