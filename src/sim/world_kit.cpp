#include "world_kit.hpp"

#include <algorithm>
#include <cmath>

namespace mcslam::sim::kit {

namespace {

Mat3 yawMatrix(double yaw) { return Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix(); }

// Pose of a part placed at local (x, y, z) of a piece at c turned by yaw.
SE3 partPose(const Vec2& c, double yaw, const Vec3& local) {
  const Mat3 R = yawMatrix(yaw);
  return SE3(R, Vec3(c.x(), c.y(), 0.0) + R * local);
}

// A box part of a piece: local centre and half extents, one material everywhere or a distinct front (+x).
void part(WorldBuilder& b, const Vec2& c, double yaw, const Vec3& centre, const Vec3& half, const Material& m) {
  b.addBox(partPose(c, yaw, centre), half, m);
}
void partWithFront(WorldBuilder& b, const Vec2& c, double yaw, const Vec3& centre, const Vec3& half,
                   const Material& body, const Material& front) {
  std::array<Material, 6> faces;
  faces.fill(body);
  faces[kBoxPlusX] = front;
  b.addBox(partPose(c, yaw, centre), half, faces);
}

Material wood(Rng& rng) { return Material::texture(TextureKind::WoodPanel, rng.uniform(0.7, 1.2), 0.0015); }
Material metal(Rng& rng) { return Material::texture(TextureKind::Metal, rng.uniform(0.5, 1.1), 0.001); }
Material fabric(Rng& rng) { return Material::texture(TextureKind::Fabric, rng.uniform(0.6, 1.2), 0.001); }

// Thin panel on a wall: front shows `front`, centred on the surface point `out` metres off the wall.
void wallPanel(WorldBuilder& b, const Wall& w, bool left_side, double along, double z, double width, double height,
               double thickness, const Material& front, const Material& back) {
  const Vec2 n2 = left_side ? w.leftNormal() : Vec2(-w.leftNormal());
  const Vec3 n(n2.x(), n2.y(), 0.0);
  b.addPanel(w.surfacePoint(left_side, along, z, 0.0005 + 0.5 * thickness), n, Vec3::UnitZ(), width, height, front,
             back, thickness);
}

}  // namespace

Vec3 Wall::surfacePoint(bool left_side, double along, double z, double out) const {
  const Vec2 n = left_side ? leftNormal() : Vec2(-leftNormal());
  const Vec2 p = a + dir() * along + n * (0.5 * thickness + out);
  return Vec3(p.x(), p.y(), z);
}

void addWall(WorldBuilder& b, const Wall& w, const Material& left, const Material& right,
             const std::vector<Opening>& openings) {
  const double len = w.length(), yaw = std::atan2(w.dir().y(), w.dir().x());
  std::array<Material, 6> faces;
  faces.fill(left);
  faces[kBoxMinusY] = right;             // the local +y face looks to the left of a->b
  const double ext = 0.5 * w.thickness;  // ends overlap the walls they meet: no cracks at corners
  auto piece = [&](double from, double to, double z0, double z1) {
    if (to - from < 1e-4 || z1 - z0 < 1e-4) return;
    const double f = from <= 0 ? from - ext : from, t = to >= len ? to + ext : to;
    const Vec2 mid = w.a + w.dir() * (0.5 * (f + t));
    b.addBox(SE3(yawMatrix(yaw), Vec3(mid.x(), mid.y(), 0.5 * (z0 + z1))),
             Vec3(0.5 * (t - f), 0.5 * w.thickness, 0.5 * (z1 - z0)), faces);
  };
  std::vector<Opening> sorted = openings;
  std::sort(sorted.begin(), sorted.end(), [](const Opening& x, const Opening& y) { return x.from < y.from; });
  double pos = 0;
  for (const Opening& o : sorted) {
    piece(pos, o.from, 0, w.height);
    piece(o.from, o.to, 0, o.bottom);
    piece(o.from, o.to, o.top, w.height);
    pos = o.to;
  }
  piece(pos, len, 0, w.height);
}

void addFloor(WorldBuilder& b, const Vec2& lo, const Vec2& hi, const Material& m) {
  b.addBox(Vec3(lo.x(), lo.y(), -0.05), Vec3(hi.x(), hi.y(), 0.0), m);
}

void addCeiling(WorldBuilder& b, const Vec2& lo, const Vec2& hi, double height, const Material& m) {
  b.addBox(Vec3(lo.x(), lo.y(), height), Vec3(hi.x(), hi.y(), height + 0.05), m);
}

void addCeilingLight(WorldBuilder& b, const Vec2& at, double height, double intensity) {
  b.addBox(Vec3(at.x() - 0.3, at.y() - 0.3, height - 0.02), Vec3(at.x() + 0.3, at.y() + 0.3, height),
           Material::lamp(2.5));
  b.addLight({Vec3(at.x(), at.y(), height - 0.1), intensity, 0.25, 12.0});
}

void addPoster(WorldBuilder& b, const Wall& w, bool left_side, double along, double z, double width, double height) {
  wallPanel(b, w, left_side, along, z, width, height, 0.002, Material::fitted(TextureKind::Poster),
            Material::uniform(0.8));
}

void addNoticeBoard(WorldBuilder& b, const Wall& w, bool left_side, double along, double z, double width,
                    double height) {
  wallPanel(b, w, left_side, along, z, width, height, 0.02, Material::fitted(TextureKind::NoticeBoard),
            Material::uniform(0.5));
}

void addWhiteboard(WorldBuilder& b, const Wall& w, bool left_side, double along, double z, double width,
                   double height) {
  wallPanel(b, w, left_side, along, z, width, height, 0.015, Material::fitted(TextureKind::Whiteboard),
            Material::uniform(0.6));
}

void addDoor(WorldBuilder& b, const Wall& w, bool left_side, double along, double width) {
  const double h = 2.05;
  wallPanel(b, w, left_side, along, 0.5 * h, width, h, 0.03, Material::fitted(TextureKind::Door),
            Material::uniform(0.5));
  const Material frame = Material::uniform(0.25);
  const double fw = 0.06;  // frame: two jambs and a head
  wallPanel(b, w, left_side, along - 0.5 * width - 0.5 * fw, 0.5 * (h + fw), fw, h + fw, 0.045, frame, frame);
  wallPanel(b, w, left_side, along + 0.5 * width + 0.5 * fw, 0.5 * (h + fw), fw, h + fw, 0.045, frame, frame);
  wallPanel(b, w, left_side, along, h + 0.5 * fw, width, fw, 0.045, frame, frame);
}

void addRadiator(WorldBuilder& b, const Wall& w, bool left_side, double along, double width) {
  wallPanel(b, w, left_side, along, 0.45, width, 0.6, 0.08, Material::texture(TextureKind::Radiator, 1.0, 0.002),
            Material::uniform(0.7));
}

void addWindow(WorldBuilder& b, const Wall& w, bool left_side, double along, double width, double bottom, double top) {
  // Frosted glass: self-lit, a little brighter than the walls; with a frame and a mullion.
  wallPanel(b, w, left_side, along, 0.5 * (bottom + top), width, top - bottom, 0.004, Material::lamp(1.2),
            Material::uniform(0.5));
  const Material frame = Material::uniform(0.75);
  const double f = 0.05;
  wallPanel(b, w, left_side, along, bottom, width + 2 * f, f, 0.06, frame, frame);
  wallPanel(b, w, left_side, along, top, width + 2 * f, f, 0.06, frame, frame);
  wallPanel(b, w, left_side, along - 0.5 * width, 0.5 * (bottom + top), f, top - bottom, 0.06, frame, frame);
  wallPanel(b, w, left_side, along + 0.5 * width, 0.5 * (bottom + top), f, top - bottom, 0.06, frame, frame);
  wallPanel(b, w, left_side, along, 0.5 * (bottom + top), 0.03, top - bottom, 0.05, frame, frame);
}

void addSkirting(WorldBuilder& b, const Wall& w, bool left_side, double from, double to) {
  wallPanel(b, w, left_side, 0.5 * (from + to), 0.04, to - from, 0.08, 0.012, Material::uniform(0.12),
            Material::uniform(0.12));
}

Vec2 turnedHalf(double yaw, double length, double width) {
  const double c = std::abs(std::cos(yaw)), s = std::abs(std::sin(yaw));
  return Vec2(0.5 * (c * length + s * width), 0.5 * (s * length + c * width));
}

void addTable(WorldBuilder& b, Rng& rng, const Vec2& c, double yaw, double length, double width, double height) {
  const Material top = wood(rng), legs = metal(rng);
  part(b, c, yaw, Vec3(0, 0, height - 0.015), Vec3(0.5 * length, 0.5 * width, 0.015), top);
  for (int sx : {-1, 1}) {
    for (int sy : {-1, 1}) {
      part(b, c, yaw, Vec3(sx * (0.5 * length - 0.06), sy * (0.5 * width - 0.06), 0.5 * (height - 0.03)),
           Vec3(0.02, 0.02, 0.5 * (height - 0.03)), legs);
    }
  }
}

void addChair(WorldBuilder& b, Rng& rng, const Vec2& c, double yaw) {
  const Material seat = fabric(rng), frame = metal(rng);
  part(b, c, yaw, Vec3(0, 0, 0.46), Vec3(0.23, 0.23, 0.035), seat);
  part(b, c, yaw, Vec3(-0.22, 0, 0.78), Vec3(0.03, 0.22, 0.25), seat);  // back rest behind (-x)
  b.addCylinder(partPose(c, yaw, Vec3(0, 0, 0.22)), 0.025, 0.2, frame, frame);
  b.addCylinder(partPose(c, yaw, Vec3(0, 0, 0.03)), 0.28, 0.025, frame, frame);
}

void addDesk(WorldBuilder& b, Rng& rng, const Vec2& c, double yaw) {
  addTable(b, rng, c, yaw, 1.4, 0.7);
  // Monitor on the far side, screen facing the chair (-x side of the desk).
  std::array<Material, 6> screen;
  screen.fill(Material::uniform(0.08));
  screen[kBoxMinusX] = Material::fitted(TextureKind::Poster, 600 + rng.integer(0, 7), 0.8);
  b.addBox(partPose(c, yaw, Vec3(0.2, 0.1 * rng.uniform(-1, 1), 1.03)), Vec3(0.015, 0.28, 0.18), screen);
  part(b, c, yaw, Vec3(0.23, 0, 0.8), Vec3(0.02, 0.04, 0.06), Material::uniform(0.1));
  // Keyboard and a drawer unit.
  part(b, c, yaw, Vec3(-0.1, 0, 0.745), Vec3(0.08, 0.22, 0.01), Material::uniform(0.15));
  partWithFront(b, c, yaw + M_PI, Vec3(0.0, -0.45, 0.3), Vec3(0.3, 0.2, 0.3), wood(rng),
                Material::fitted(TextureKind::Cabinet));
  addChair(b, rng, c + (Eigen::Rotation2Dd(yaw) * Vec2(-0.75, 0.0)), yaw);
}

void addCabinet(WorldBuilder& b, Rng& rng, const Vec2& c, double yaw, double width, double depth, double height) {
  partWithFront(b, c, yaw, Vec3(0, 0, 0.5 * height), Vec3(0.5 * depth, 0.5 * width, 0.5 * height), wood(rng),
                Material::fitted(TextureKind::Cabinet));
}

void addBookshelf(WorldBuilder& b, Rng& rng, const Vec2& c, double yaw, double width, double height) {
  partWithFront(b, c, yaw, Vec3(0, 0, 0.5 * height), Vec3(0.17, 0.5 * width, 0.5 * height), wood(rng),
                Material::fitted(TextureKind::Books));
}

void addSofa(WorldBuilder& b, Rng& rng, const Vec2& c, double yaw, double length) {
  const Material m = fabric(rng);
  part(b, c, yaw, Vec3(0.05, 0, 0.21), Vec3(0.38, 0.5 * length, 0.21), m);
  part(b, c, yaw, Vec3(-0.35, 0, 0.6), Vec3(0.1, 0.5 * length, 0.2), m);
  part(b, c, yaw, Vec3(0.0, 0.5 * length - 0.1, 0.5), Vec3(0.4, 0.1, 0.12), m);
  part(b, c, yaw, Vec3(0.0, -0.5 * length + 0.1, 0.5), Vec3(0.4, 0.1, 0.12), m);
}

void addPlant(WorldBuilder& b, Rng& rng, const Vec2& c, double height) {
  b.addCylinder(SE3(Mat3::Identity(), Vec3(c.x(), c.y(), 0.18)), 0.2, 0.18,
                Material::texture(TextureKind::Concrete, rng.uniform(0.6, 1.2), 0.001), Material::uniform(0.15));
  const double h = std::max(0.3, height - 0.36);
  b.addCylinder(SE3(yawMatrix(rng.uniform(0, 2 * M_PI)), Vec3(c.x(), c.y(), 0.36 + 0.5 * h)), 0.36, 0.5 * h,
                Material::texture(TextureKind::Foliage, 1.0, 0.0012),
                Material::texture(TextureKind::Foliage, 1.0, 0.0012));
}

void addBin(WorldBuilder& b, Rng& rng, const Vec2& c) {
  b.addCylinder(SE3(Mat3::Identity(), Vec3(c.x(), c.y(), 0.2)), 0.15, 0.2, metal(rng), Material::uniform(0.1));
}

void addCrates(WorldBuilder& b, Rng& rng, const Vec2& c, double yaw) {
  double z = 0;
  for (int i = 0, n = rng.integer(1, 3); i < n; ++i) {
    const double w = rng.uniform(0.35, 0.6), d = rng.uniform(0.3, 0.5), h = rng.uniform(0.25, 0.45);
    const Material body = Material::texture(TextureKind::WoodPanel, rng.uniform(0.5, 0.9), 0.003);
    partWithFront(b, c, yaw, Vec3(rng.uniform(-0.04, 0.04), rng.uniform(-0.04, 0.04), z + 0.5 * h),
                  Vec3(0.5 * d, 0.5 * w, 0.5 * h), body,
                  Material::fitted(TextureKind::Poster, 500 + rng.integer(0, 7)));
    z += h;
  }
}

void addPillar(WorldBuilder& b, const Vec2& c, double radius, double height, const Material& m) {
  b.addCylinder(SE3(Mat3::Identity(), Vec3(c.x(), c.y(), 0.5 * height)), radius, 0.5 * height, m, m);
}

}  // namespace mcslam::sim::kit
