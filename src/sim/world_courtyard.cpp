// "courtyard": an outdoor square about 50 x 36 m closed by building facades (11-17 m high, 15-40 m from the
// loop), with a planted centre, trees, benches, lamp posts and parked cars; sun with shadows and a sky.
// The loop (about 80 m) goes round the planted centre.
#include <cmath>

#include "world_layout.hpp"
#include "world_named.hpp"

namespace mcslam::sim {

namespace {

Mat3 yawMatrix(double yaw) { return Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix(); }

void addTree(WorldBuilder& b, Rng& rng, const Vec2& c) {
  const double trunk_h = rng.uniform(2.2, 3.2), crown_r = rng.uniform(1.3, 2.2), crown_h = rng.uniform(2.5, 4.0);
  b.addCylinder(SE3(yawMatrix(rng.uniform(0, 6.28)), Vec3(c.x(), c.y(), 0.5 * trunk_h + 0.1)), rng.uniform(0.12, 0.22),
                0.5 * trunk_h + 0.1, Material::texture(TextureKind::Bark, 1.0, 0.0015), Material::uniform(0.2));
  // The crown: a few overlapping drums of leaves, for a lumpy outline.
  const Material leaves = Material::texture(TextureKind::Foliage, rng.uniform(0.8, 1.2), 0.004);
  for (int k = 0; k < 4; ++k) {
    const double r = crown_r * (k == 0 ? 1.0 : rng.uniform(0.5, 0.8)),
                 h = crown_h * (k == 0 ? 0.7 : rng.uniform(0.4, 0.6));
    const Vec2 off = k == 0 ? Vec2(0, 0) : Vec2(Vec2(rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5)) * crown_r);
    const double z = trunk_h + (k == 0 ? 0.45 * crown_h : rng.uniform(0.3, 0.8) * crown_h);
    b.addCylinder(SE3(yawMatrix(rng.uniform(0, 6.28)), Vec3(c.x() + off.x(), c.y() + off.y(), z)), r, 0.5 * h, leaves,
                  leaves);
  }
}

void addBench(WorldBuilder& b, Rng& rng, const Vec2& c, double yaw) {
  const Mat3 R = yawMatrix(yaw);
  const Material slats = Material::texture(TextureKind::WoodPlanks, rng.uniform(0.6, 1.0), 0.001);
  const Material iron = Material::uniform(0.08);
  auto at = [&](double x, double y, double z) { return SE3(R, Vec3(c.x(), c.y(), 0) + R * Vec3(x, y, z)); };
  b.addBox(at(0, 0, 0.44), Vec3(0.22, 0.9, 0.03), slats);
  b.addBox(at(-0.22, 0, 0.72), Vec3(0.03, 0.9, 0.2), slats);
  for (double y : {-0.75, 0.75}) b.addBox(at(0, y, 0.21), Vec3(0.2, 0.03, 0.21), iron);
}

void addLamp(WorldBuilder& b, const Vec2& c) {
  const Material iron = Material::uniform(0.1);
  b.addCylinder(SE3(Mat3::Identity(), Vec3(c.x(), c.y(), 2.0)), 0.06, 2.0, iron, iron);
  b.addBox(Vec3(c.x() - 0.2, c.y() - 0.2, 4.0), Vec3(c.x() + 0.2, c.y() + 0.2, 4.35), Material::uniform(0.6));
}

void addCar(WorldBuilder& b, Rng& rng, const Vec2& c, double yaw) {
  const Mat3 R = yawMatrix(yaw);
  const Material body = Material::texture(TextureKind::Metal, rng.uniform(0.2, 1.4), 0.004);
  const Material glass = Material::uniform(0.05);
  auto at = [&](double x, double z) { return SE3(R, Vec3(c.x(), c.y(), 0) + R * Vec3(x, 0, z)); };
  b.addBox(at(0, 0.55), Vec3(2.25, 0.88, 0.38), body);
  std::array<Material, 6> cabin;
  cabin.fill(glass);
  cabin[kBoxPlusZ] = body;
  b.addBox(at(-0.2, 1.15), Vec3(1.2, 0.8, 0.25), cabin);
  for (double x : {-1.4, 1.4}) {
    for (double y : {-0.85, 0.85}) {
      b.addCylinder(SE3(R * Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()).toRotationMatrix(),
                        Vec3(c.x(), c.y(), 0.32) + R * Vec3(x, y, 0)),
                    0.32, 0.1, Material::uniform(0.04), Material::uniform(0.2));
    }
  }
}

// Ground: paving in the square, and round it (coarser light map) out to the far buildings; an asphalt strip
// for parking along the south side.
void addGround(WorldBuilder& b) {
  const Material paving = Material::texture(TextureKind::Paving, 1.0, 0.0025);
  b.addBox(Vec3(-27, -20, -0.1), Vec3(26, 18, 0.0), paving);
  b.addBox(Vec3(-80, -80, -0.1), Vec3(80, -20, 0.0), paving);
  b.addBox(Vec3(-80, 18, -0.1), Vec3(80, 80, 0.0), paving);
  b.addBox(Vec3(-80, -20, -0.1), Vec3(-27, 18, 0.0), paving);
  b.addBox(Vec3(26, -20, -0.1), Vec3(80, 18, 0.0), paving);
  b.addBox(Vec3(-24, -17.5, 0.0), Vec3(24, -12.5, 0.005), Material::texture(TextureKind::Asphalt, 1.0, 0.003));
}

// Buildings round the square, and a taller one seen through the gap in the north-east corner.
void addBuildings(WorldBuilder& b, Rng& rng) {
  struct Building {
    Vec3 lo, hi;
  };
  const Building buildings[] = {
      {Vec3(-40, 18, 0), Vec3(18, 30, 11.0)}, {Vec3(-40, -32, 0), Vec3(30, -20, 9.5)},
      {Vec3(26, -20, 0), Vec3(38, 12, 13.0)}, {Vec3(-40, -20, 0), Vec3(-27, 18, 10.0)},
      {Vec3(34, 30, 0), Vec3(64, 52, 22.0)},
  };
  for (const Building& bd : buildings) {
    b.addBox(bd.lo, bd.hi, Material::texture(TextureKind::Facade, rng.uniform(0.8, 1.15), 0.012));
  }
}

// Planted centre: hedges round a lawn, trees, and benches facing the path.
void addPlantedCentre(WorldBuilder& b, Rng& rng) {
  b.addBox(Vec3(-7, -4, 0), Vec3(7, 4, 0.03), Material::texture(TextureKind::Grass, 1.0, 0.003));
  const Material hedge = Material::texture(TextureKind::Foliage, 1.0, 0.003);
  b.addBox(Vec3(-7, -4.6, 0), Vec3(7, -4.0, 0.9), hedge);
  b.addBox(Vec3(-7, 4.0, 0), Vec3(7, 4.6, 0.9), hedge);
  for (double x : {-4.0, 0.0, 4.0}) addTree(b, rng, Vec2(x + rng.uniform(-0.5, 0.5), rng.uniform(-1.0, 1.0)));
  for (double x : {-5.0, 5.0}) {
    addBench(b, rng, Vec2(x, -5.6), -M_PI / 2);
    addBench(b, rng, Vec2(x, 5.6), M_PI / 2);
  }
}

// Outer ring: trees, lamps, bins, a kiosk and parked cars, away from the loop and the lanes of `keep` (each
// piece placed becomes a lane of its own, so that the later ones keep their distance).
void addOuterRing(WorldBuilder& b, Rng& rng, layout::KeepOut& keep) {
  const Vec2 lo(-26, -19), hi(25, 17.5);
  for (int placed = 0, tries = 0; tries < 400 && placed < 22; ++tries) {
    const Vec2 c(rng.uniform(lo.x() + 1, hi.x() - 1), rng.uniform(lo.y() + 1, hi.y() - 1));
    if (std::abs(c.x()) < 16 && std::abs(c.y()) < 12) continue;  // keep the loop's surroundings open
    const int kind = placed % 4;
    const Vec2 half = kind == 0 ? Vec2(2.3, 2.3) : Vec2(0.5, 0.5);
    if (!keep.clear(c, half, lo, hi)) continue;
    keep.lanes.push_back({c, c});  // later pieces keep their distance
    if (kind == 0)
      addTree(b, rng, c);
    else if (kind == 1)
      addLamp(b, c);
    else if (kind == 2)
      kit::addBin(b, rng, c);
    else
      kit::addPlant(b, rng, c, 1.6);
    ++placed;
  }
  for (double x = -20.0; x < 20.0; x += rng.uniform(5.5, 8.0)) addCar(b, rng, Vec2(x, -15.0), 0.0);
  b.addBox(Vec3(18, 12, 0), Vec3(21, 15, 2.8), Material::fitted(TextureKind::Poster));  // kiosk
  for (double x : {-16.0, -8.0, 8.0, 16.0}) addLamp(b, Vec2(x, 11.5));
}

}  // namespace

std::shared_ptr<const World> buildCourtyardWorld(const WorldOptions& options) {
  WorldBuilder b(options.seed, "courtyard", options.textures_dir);
  Rng rng(hashOf(options.seed, 0xc0a7));

  RouteSpec route;
  route.corners = {Vec2(-12, -8.5), Vec2(12, -8.5), Vec2(12, 8.5), Vec2(-12, 8.5)};
  route.radii = {2.5, 1.5, 2.5, 1.5};
  route.stops = {2};
  route.clearance = 0.6;
  const RouteCurve curve(route);

  addGround(b);
  addBuildings(b, rng);
  addPlantedCentre(b, rng);
  layout::KeepOut keep;
  keep.route = &curve;
  keep.route_margin = 1.6;
  keep.lanes = {{Vec2(-20, 14.5), Vec2(14, 14.5)}, {Vec2(-22, -11.0), Vec2(-22, 11.0)}};
  keep.lane_margin = 0.8;
  addOuterRing(b, rng, keep);

  if (options.moving_objects) {  // people walking along the two lanes
    const double speeds[] = {1.3, 1.2};
    for (int i = 0; i < 2; ++i) {
      Walker w;
      w.a = keep.lanes[i].first;
      w.b = keep.lanes[i].second;
      w.speed = speeds[i];
      w.phase = 2.0 * i;
      b.addWalker(w);
    }
  }

  b.setSun(Vec3(0.45, -0.35, 0.8), 3.2);
  b.setAmbient(0.9, 0.3, 40.0);
  b.setSky(3.5, 2.2);
  b.setExposure(0.28);
  b.setLightmapCell(0.3);
  b.setRoute(route);
  return b.build();
}

}  // namespace mcslam::sim
