#include <algorithm>
#include <cmath>

#include "mcslam/core/error.hpp"
#include "world_data.hpp"

namespace mcslam::sim {

using detail::Prim;
using detail::WorldData;

const char* textureKindName(TextureKind kind) {
  static const char* kNames[] = {"plaster", "concrete", "brick",   "wood-planks", "wood-panel", "tiles",  "linoleum",
                                 "carpet",  "fabric",   "metal",   "ceiling",     "poster",     "notice", "whiteboard",
                                 "books",   "door",     "cabinet", "facade",      "paving",     "grass",  "foliage",
                                 "bark",    "asphalt",  "person",  "radiator"};
  const int i = static_cast<int>(kind);
  return i >= 0 && i < static_cast<int>(TextureKind::Count) ? kNames[i] : "?";
}

// ---- World ----

World::World(std::shared_ptr<const detail::WorldData> data) : data_(std::move(data)) {}

const std::string& World::name() const { return data_->name; }
uint64_t World::seed() const { return data_->seed; }
const RouteSpec& World::route() const { return data_->route; }
int World::staticObjectCount() const { return static_cast<int>(data_->prims.size()); }
int World::walkerCount() const { return static_cast<int>(data_->walkers.size()); }
SE3 World::walkerPose(int i, double time_s) const { return data_->walkerPose(i, time_s); }
double World::exposure() const { return data_->exposure; }

std::pair<Vec3, Vec3> World::bounds() const {
  Vec3 lo = Vec3::Constant(1e30), hi = Vec3::Constant(-1e30);
  for (const Prim& p : data_->prims) {
    float a[3], b[3];
    p.aabb(a, b);
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], static_cast<double>(a[k]));
      hi[k] = std::max(hi[k], static_cast<double>(b[k]));
    }
  }
  return {lo, hi};
}

std::optional<RayHit> World::intersect(const Vec3& origin, const Vec3& direction, double t_max, double time_s,
                                       bool include_moving) const {
  const Vec3 dir = direction.normalized();
  const float O[3] = {static_cast<float>(origin.x()), static_cast<float>(origin.y()), static_cast<float>(origin.z())};
  const float D[3] = {static_cast<float>(dir.x()), static_cast<float>(dir.y()), static_cast<float>(dir.z())};
  float best_t = static_cast<float>(std::min(t_max, 1e30));
  int face = 0;
  Prim hit_prim{};
  bool moving = false;
  int object = data_->bvh.closest(data_->prims, O, D, detail::kRayEpsilon, best_t, best_t, face);
  if (object >= 0) hit_prim = data_->prims[object];
  if (include_moving) {
    for (int i = 0; i < walkerCount(); ++i) {
      const Prim p = data_->walkerPrim(i, time_s);
      float o[3], d[3], t;
      int f;
      p.localOrigin(O, o);
      p.toLocal(D, d);
      if (detail::intersectLocal(p, o, d, detail::kRayEpsilon, best_t, t, f)) {
        best_t = t;
        face = f;
        object = i;
        hit_prim = p;
        moving = true;
      }
    }
  }
  if (object < 0) return std::nullopt;
  RayHit hit;
  hit.t = best_t;
  hit.point = origin + dir * hit.t;
  hit.object = object;
  hit.face = face;
  hit.moving = moving;
  float o[3], d[3], q[3], n[3], nw[3];
  hit_prim.localOrigin(O, o);
  hit_prim.toLocal(D, d);
  for (int k = 0; k < 3; ++k) q[k] = o[k] + best_t * d[k];
  detail::faceNormal(hit_prim, face, q, n);
  hit_prim.toWorld(n, nw);
  hit.normal = Vec3(nw[0], nw[1], nw[2]).normalized();
  return hit;
}

// ---- Walkers ----

namespace detail {

SE3 WorldData::walkerPose(int i, double t) const {
  const Walker& w = walkers.at(i);
  const Vec2 ab = w.b - w.a;
  const double len = std::max(ab.norm(), 1e-6);
  // Cosine easing between the ends: peak speed pi * len / (2 * half_period).
  const double half_period = M_PI * len / (2.0 * std::max(w.speed, 0.05));
  double phi = std::fmod((t + w.phase) / half_period, 2.0);
  if (phi < 0) phi += 2.0;
  const double s = phi < 1.0 ? 0.5 * (1 - std::cos(M_PI * phi)) : 0.5 * (1 + std::cos(M_PI * (phi - 1.0)));
  const Vec2 p = w.a + s * ab;
  // Turn round smoothly near each end (phi around 0/2 and 1).
  auto ramp = [](double x) { return x <= 0 ? 0.0 : (x >= 1 ? 1.0 : x * x * (3 - 2 * x)); };
  const double turn =
      ramp((phi - 0.92) / 0.16) + ramp((phi - 1.92) / 0.16) + (phi < 0.08 ? ramp((phi + 0.08) / 0.16) - 1 : 0);
  const double yaw = std::atan2(ab.y(), ab.x()) + M_PI * turn;
  // Slight bob while walking.
  const double bob = 0.02 * std::abs(std::sin(M_PI * s * len / 0.7));
  return SE3(Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix(), Vec3(p.x(), p.y(), w.half_extents.z() + bob));
}

Prim WorldData::walkerPrim(int i, double t) const {
  return Prim::box(walkerPose(i, t), walkers[i].half_extents, walker_face0[i]);
}

float WorldData::unlitIrradiance(const Vec3& n) const {
  // Ambient from above is brighter than from below; sun or ceiling lights add a directional part.
  const double up = 0.5 * (1.0 + n.z());
  double e = ambient_open * (0.6 + 0.6 * up);
  if (sun_irradiance > 0)
    e += sun_irradiance * std::max(0.0, n.dot(sun_direction)) * 0.8;
  else if (!lights.empty())
    e += lights.front().intensity * 0.08 * (0.5 + 0.5 * up);
  return static_cast<float>(e);
}

}  // namespace detail

}  // namespace mcslam::sim
