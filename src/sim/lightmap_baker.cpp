#include "lightmap_baker.hpp"

#include <algorithm>
#include <cmath>

#include "hash.hpp"
#include "mcslam/core/worker_pool.hpp"
#include "world_data.hpp"

namespace mcslam::sim {

using detail::LightmapRecord;
using detail::Prim;
using detail::WorldData;

namespace {

constexpr int kAmbientGrid = 4;  // 4 x 4 stratified, cosine-weighted directions
constexpr int kAmbientSamples = kAmbientGrid * kAmbientGrid;
constexpr int kLightSamples = 3;       // points on each light's disc, for soft shadows
constexpr float kOffset = 0.002f;      // start rays this far off the surface
constexpr float kIgnoreNear = 0.003f;  // occluders nearer than this (posters on walls) cast no shadow
constexpr int kMaxCellsPerSide = 600;
constexpr double kMaxCellsPerFace = 60000;  // large far-away faces get coarser cells

struct Frame {  // world point and unit normal of a cell
  float p[3], n[3];
};

Frame cellFrame(const Prim& prim, int face, float u, float v) {
  float q[3], nl[3], pw[3];
  detail::facePoint(prim, face, u, v, q);
  detail::faceNormal(prim, face, q, nl);
  prim.toWorld(q, pw);
  Frame f;
  prim.toWorld(nl, f.n);
  for (int k = 0; k < 3; ++k) f.p[k] = pw[k] + prim.c[k] + kOffset * f.n[k];
  return f;
}

// Orthonormal tangents of a unit normal.
void tangents(const float n[3], float t[3], float b[3]) {
  const Vec3 nn(n[0], n[1], n[2]);
  const Vec3 a = std::abs(nn.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 tt = nn.cross(a).normalized(), bb = nn.cross(tt);
  for (int k = 0; k < 3; ++k) {
    t[k] = static_cast<float>(tt[k]);
    b[k] = static_cast<float>(bb[k]);
  }
}

float irradiance(const WorldData& w, const Frame& f, uint64_t cell_seed) {
  float e = 0.f;
  const Vec3 p(f.p[0], f.p[1], f.p[2]), n(f.n[0], f.n[1], f.n[2]);
  float t[3], b[3];
  tangents(f.n, t, b);
  for (const PointLight& L : w.lights) {
    const Vec3 to = L.position - p;
    const double dist = to.norm();
    if (dist > L.range || dist < 1e-3) continue;
    const double cos_i = n.dot(to) / dist;
    if (cos_i <= 0) continue;
    // Light disc samples around the light centre, in the plane facing the point.
    int visible = 0;
    const Vec3 dir = to / dist;
    const Vec3 ax = (std::abs(dir.z()) < 0.9 ? dir.cross(Vec3::UnitZ()) : dir.cross(Vec3::UnitX())).normalized();
    const Vec3 ay = dir.cross(ax);
    const double rot = 2 * M_PI * unitFromHash(hashOf(cell_seed, 5));
    for (int s = 0; s < kLightSamples; ++s) {
      const double a = rot + 2 * M_PI * s / kLightSamples, r = L.radius * std::sqrt((s + 0.5) / kLightSamples);
      const Vec3 target = L.position + r * (std::cos(a) * ax + std::sin(a) * ay);
      const Vec3 d = target - p;
      const double len = d.norm();
      const float D[3] = {static_cast<float>(d.x() / len), static_cast<float>(d.y() / len),
                          static_cast<float>(d.z() / len)};
      if (!w.bvh.occluded(w.prims, f.p, D, kIgnoreNear, static_cast<float>(len) - 0.02f)) ++visible;
    }
    // Inverse square with a soft core so surfaces right next to a lamp do not blow up.
    e += static_cast<float>(L.intensity * cos_i / std::max(dist * dist, 0.5) * visible / kLightSamples);
  }
  if (w.sun_irradiance > 0) {
    const double cos_s = n.dot(w.sun_direction);
    if (cos_s > 0) {
      const float D[3] = {static_cast<float>(w.sun_direction.x()), static_cast<float>(w.sun_direction.y()),
                          static_cast<float>(w.sun_direction.z())};
      if (!w.bvh.occluded(w.prims, f.p, D, kIgnoreNear, 1e4f)) e += static_cast<float>(w.sun_irradiance * cos_s);
    }
  }
  // Ambient: cosine-weighted stratified directions, each either open or blocked within the ambient range.
  const double rot = 2 * M_PI * unitFromHash(hashOf(cell_seed, 9));
  float amb = 0.f;
  for (int i = 0; i < kAmbientGrid; ++i) {
    for (int j = 0; j < kAmbientGrid; ++j) {
      const double u1 = (i + unitFromHash(hashOf(cell_seed, i, j))) / kAmbientGrid;
      const double u2 = (j + unitFromHash(hashOf(cell_seed, j, i, 3))) / kAmbientGrid;
      const double r = std::sqrt(u1), phi = rot + 2 * M_PI * u2;
      const float x = static_cast<float>(r * std::cos(phi)), y = static_cast<float>(r * std::sin(phi));
      const float z = static_cast<float>(std::sqrt(std::max(0.0, 1.0 - u1)));
      const float D[3] = {x * t[0] + y * b[0] + z * f.n[0], x * t[1] + y * b[1] + z * f.n[1],
                          x * t[2] + y * b[2] + z * f.n[2]};
      const bool blocked = w.bvh.occluded(w.prims, f.p, D, kIgnoreNear, static_cast<float>(w.ambient_range));
      // Open sky is brighter above the horizon than below it (ground bounce).
      const float open = static_cast<float>(w.ambient_open) * (D[2] >= 0 ? 1.f : 0.6f);
      amb += blocked ? static_cast<float>(w.ambient_occluded) : open;
    }
  }
  return e + amb / kAmbientSamples;
}

// A [1 2 1] / 4 blur in both directions (clamped at the borders): hides the sampling noise of the ambient
// estimate, and softens shadow edges by about a cell, as real penumbrae are soft.
void smooth(float* v, int w, int h) {
  std::vector<float> tmp(static_cast<std::size_t>(w) * h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const float* r = v + static_cast<std::size_t>(y) * w;
      tmp[static_cast<std::size_t>(y) * w + x] =
          0.25f * r[std::max(0, x - 1)] + 0.5f * r[x] + 0.25f * r[std::min(w - 1, x + 1)];
    }
  }
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const auto at = [&](int yy) { return tmp[static_cast<std::size_t>(std::clamp(yy, 0, h - 1)) * w + x]; };
      v[static_cast<std::size_t>(y) * w + x] = 0.25f * at(y - 1) + 0.5f * at(y) + 0.25f * at(y + 1);
    }
  }
}

// True when the face lies inside other objects (wall tops under the ceiling slab, bottoms on the floor, ends
// inside the next wall): nobody sees it, so it needs no light map.
bool buried(const WorldData& w, int prim, int face) {
  const Prim& p = w.prims[prim];
  float fw, fh;
  detail::faceSize(p, face, fw, fh);
  const float us[5] = {0.5f, 0.01f, 0.99f, 0.01f, 0.99f}, vs[5] = {0.5f, 0.01f, 0.01f, 0.99f, 0.99f};
  for (int k = 0; k < 5; ++k) {
    const Frame f = cellFrame(p, face, us[k] * fw, vs[k] * fh);
    bool inside = false;
    w.bvh.point(w.prims, f.p, [&](int other) {
      if (other == prim || inside) return;
      const Prim& o = w.prims[other];
      float q[3];
      o.localOrigin(f.p, q);
      if (o.type == detail::PrimType::Box) {
        inside = std::abs(q[0]) < o.h[0] && std::abs(q[1]) < o.h[1] && std::abs(q[2]) < o.h[2];
      } else {
        inside = q[0] * q[0] + q[1] * q[1] < o.h[0] * o.h[0] && std::abs(q[2]) < o.h[2];
      }
    });
    if (!inside) return false;
  }
  return true;
}

}  // namespace

void bakeLightmaps(WorldData& w, double cell_size, WorkerPool& pool) {
  // Allocate one grid per lit face.
  w.lightmaps.clear();
  std::size_t total = 0;
  std::vector<std::pair<int, int>> jobs;  // (prim, face)
  for (std::size_t i = 0; i < w.prims.size(); ++i) {
    const Prim& p = w.prims[i];
    for (int f = 0; f < p.faceCount(); ++f) {
      detail::FaceRecord& fr = w.faces[p.face0 + f];
      if (fr.emission > 0.f || !w.face_materials[p.face0 + f].lit || buried(w, static_cast<int>(i), f)) continue;
      float fw, fh;
      detail::faceSize(p, f, fw, fh);
      LightmapRecord lm;
      lm.w = std::clamp(static_cast<int>(std::ceil(fw / cell_size)), 2, kMaxCellsPerSide);
      lm.h = std::clamp(static_cast<int>(std::ceil(fh / cell_size)), 2, kMaxCellsPerSide);
      if (static_cast<double>(lm.w) * lm.h > kMaxCellsPerFace) {
        const double shrink = std::sqrt(static_cast<double>(lm.w) * lm.h / kMaxCellsPerFace);
        lm.w = std::max(2, static_cast<int>(lm.w / shrink));
        lm.h = std::max(2, static_cast<int>(lm.h / shrink));
      }
      lm.su = lm.w / std::max(fw, 1e-5f);
      lm.sv = lm.h / std::max(fh, 1e-5f);
      lm.offset = total;
      total += static_cast<std::size_t>(lm.w) * lm.h;
      fr.lightmap = static_cast<int>(w.lightmaps.size());
      w.lightmaps.push_back(lm);
      jobs.emplace_back(static_cast<int>(i), f);
    }
  }
  w.lightmap_values.assign(total, 0.f);
  pool.forEach(static_cast<int>(jobs.size()), [&](int job) {
    const auto [pi, f] = jobs[job];
    const Prim& p = w.prims[pi];
    const LightmapRecord& lm = w.lightmaps[w.faces[p.face0 + f].lightmap];
    for (int y = 0; y < lm.h; ++y) {
      for (int x = 0; x < lm.w; ++x) {
        const Frame fr = cellFrame(p, f, (x + 0.5f) / lm.su, (y + 0.5f) / lm.sv);
        w.lightmap_values[lm.offset + static_cast<std::size_t>(y) * lm.w + x] =
            irradiance(w, fr, hashOf(w.seed, static_cast<uint64_t>(pi), static_cast<uint64_t>(f), y * 4096ULL + x));
      }
    }
    smooth(&w.lightmap_values[lm.offset], lm.w, lm.h);
  });
}

}  // namespace mcslam::sim
