#pragma once
// Placement helpers shared by the named worlds: rooms bounded by walls, furniture slots along walls that keep
// clear of the route, and wall decorations that keep clear of openings and of each other.
#include <functional>
#include <vector>

#include "route_curve.hpp"
#include "world_kit.hpp"

namespace mcslam::sim::layout {

// A wall of a room (interior on its left) with its openings and the stretches already used by decorations.
struct RoomWall {
  kit::Wall wall;
  std::vector<kit::Opening> openings;
  std::vector<std::pair<double, double>> used;  // along-wall intervals taken
  bool exterior = false;                        // outside wall (may get windows)

  bool isFree(double from, double to) const;
  void take(double from, double to) { used.emplace_back(from, to); }
};

struct Room {
  Vec2 lo, hi;
  double height = 2.8;
  std::vector<RoomWall> walls;  // counter-clockwise, interior on the left
};

// Interior rectangle [lo, hi] with walls on its border; `exterior[i]` marks walls S, E, N, W.
Room makeRoom(const Vec2& lo, const Vec2& hi, double height, const std::array<bool, 4>& exterior);

// Where furniture may not go: near the route (the robot) and near the lanes people walk along (whether or not
// the world has moving objects, so the furniture does not depend on that option).
struct KeepOut {
  const RouteCurve* route = nullptr;
  double route_margin = 1.0;
  std::vector<std::pair<Vec2, Vec2>> lanes;
  double lane_margin = 0.55;

  // Footprint (centre, half extents along x/y) inside [lo, hi] and clear of the route and lanes.
  bool clear(const Vec2& centre, const Vec2& half, const Vec2& lo, const Vec2& hi) const;
};

// Places pieces against the room's walls, every `spacing` metres, each facing into the room. place(centre, yaw)
// adds the piece; depth/width are its size across/along the wall. Slots too close to the route or to openings
// or lanes, or to openings, are skipped. Returns how many were placed.
int fillWallSlots(Room& room, Rng& rng, const KeepOut& keep_out, double width, double depth, double spacing,
                  double keep_probability, const std::function<void(const Vec2& centre, double yaw)>& place);

// Decorates the room's walls: posters, notice boards, whiteboards, doors, windows with radiators (exterior
// walls), skirting boards.
void decorateWalls(WorldBuilder& b, Room& room, Rng& rng, int items_per_wall);

// Builds the room's walls (with their openings) and its floor and ceiling, plus lights on a grid.
void buildRoom(WorldBuilder& b, Room& room, const Material& wall, const Material& outside, const Material& floor,
               const Material& ceiling, double light_spacing, double light_intensity);

}  // namespace mcslam::sim::layout
