#include "frame_context.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "bvh_cone.hpp"

namespace mcslam::sim {

using detail::FaceRecord;
using detail::Prim;

namespace {

// log2 for mip selection: exponent plus a quadratic in the mantissa (error below 0.01 level).
inline float fastLog2(float x) {
  uint32_t bits;
  std::memcpy(&bits, &x, 4);
  const float e = static_cast<float>(static_cast<int>((bits >> 23) & 255) - 127);
  bits = (bits & 0x7fffffu) | 0x3f800000u;
  float m;
  std::memcpy(&m, &bits, 4);
  return e + (-0.34484843f * m + 2.02466578f) * m - 0.67487759f;
}

// Footprints more elongated than this are filtered along their long axis (blurs grazing floors a little
// rather than letting them alias).
constexpr float kMaxAnisotropy = 2.0f;

// Whether the primitive's oriented bounding box (a cylinder's is the box around it) lies wholly behind the plane
// through O.
bool outsidePlane(const Prim& p, const float plane[3], const float O[3]) {
  float nl[3];
  p.toLocal(plane, nl);
  const float r = std::abs(nl[0]) * p.h[0] + std::abs(nl[1]) * p.h[1] + std::abs(nl[2]) * p.h[2];
  const float s = plane[0] * (p.c[0] - O[0]) + plane[1] * (p.c[1] - O[1]) + plane[2] * (p.c[2] - O[2]);
  return s + r < 0.f;
}

// Distance from the camera centre (local coordinates o) to the primitive's bounding box: no ray hits it sooner.
float boxDistance(const Prim& p, const float o[3]) {
  float d2 = 0.f;
  for (int k = 0; k < 3; ++k) {
    const float e = std::abs(o[k]) - p.h[k];
    if (e > 0.f) d2 += e * e;
  }
  return std::sqrt(d2);
}

}  // namespace

FrameContext::FrameContext(const detail::WorldData& world) : world_(world) {
  to_linear_.resize(256 * 4 + 2);
  for (std::size_t i = 0; i < to_linear_.size(); ++i) {
    to_linear_[i] = static_cast<float>(std::pow(std::min(1.0, i / (255.0 * 4)), 2.2));
  }
}

void FrameContext::setup(const SE3& T_w_c, double time_s) {
  for (int r = 0; r < 3; ++r) {
    O_[r] = static_cast<float>(T_w_c.t[r]);
    for (int c = 0; c < 3; ++c) R_[3 * r + c] = static_cast<float>(T_w_c.R(r, c));
  }
  n_static_ = static_cast<int>(world_.prims.size());
  dynamic_.clear();
  for (int i = 0; i < static_cast<int>(world_.walkers.size()); ++i) dynamic_.push_back(world_.walkerPrim(i, time_s));
  const int n = n_static_ + static_cast<int>(dynamic_.size());
  local_o_.resize(3 * static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) prim(i).localOrigin(O_, &local_o_[3 * static_cast<std::size_t>(i)]);
}

void FrameContext::collectCandidates(const CameraLut& lut, int tile, std::vector<Candidate>& cands) const {
  cands.clear();
  const CameraLut::Tile& T = lut.tiles[tile];
  if (!T.any_valid) return;
  float axis[3], planes[4][3];
  rotate(T.axis, axis);
  for (int i = 0; i < 4; ++i) rotate(T.planes[i], planes[i]);
  auto add = [&](int i) {
    const Prim& p = prim(i);
    if (T.has_planes) {
      for (const auto& plane : planes) {
        if (outsidePlane(p, plane, O_)) return;
      }
    }
    Candidate c;
    const float* o = localOrigin(i);
    for (int k = 0; k < 3; ++k) {
      c.o[k] = o[k];
      c.h[k] = p.h[k];
    }
    c.near = boxDistance(p, o);
    c.prim = static_cast<uint32_t>(i);
    c.fast = p.aligned && p.type == detail::PrimType::Box;
    cands.push_back(c);
  };
  world_.bvh.cone(world_.prims, O_, axis, T.cos_a, T.sin_a, add);
  for (int i = 0; i < static_cast<int>(dynamic_.size()); ++i) {
    if (detail::sphereMeetsCone(O_, axis, T.cos_a, T.sin_a, dynamic_[i].c, dynamic_[i].radius)) add(n_static_ + i);
  }
  std::sort(cands.begin(), cands.end(), [](const Candidate& a, const Candidate& b) {
    return a.near < b.near || (a.near == b.near && a.prim < b.prim);
  });
  cands.push_back(Candidate{{0, 0, 0}, {0, 0, 0}, INFINITY, 0, false});
}

float FrameContext::sky(const float d[3]) const {
  const float up = std::max(0.f, d[2]);
  return static_cast<float>(world_.sky_horizon + (world_.sky_zenith - world_.sky_horizon) * std::sqrt(up));
}

float FrameContext::shade(uint32_t k, float t_hit, const float d[3], float pixel_angle) const {
  const int pi = keyPrim(k), face = keyFace(k);
  const Prim& p = prim(pi);
  const FaceRecord& fr = world_.faces[p.face0 + face];
  const float* o = localOrigin(pi);
  float dl[3];
  p.toLocal(d, dl);
  // Face coordinates: texture (tx, ty), light-map cell (lx, ly), and the cosine of incidence.
  float tx, ty, lx, ly, cos_i;
  if (p.type == detail::PrimType::Box) {
    const float qa = o[fr.axis_u] + t_hit * dl[fr.axis_u], qb = o[fr.axis_v] + t_hit * dl[fr.axis_v];
    tx = qa * fr.tex_u[0] + fr.tex_u[1];
    ty = qb * fr.tex_v[0] + fr.tex_v[1];
    lx = qa * fr.lm_u[0] + fr.lm_u[1];
    ly = qb * fr.lm_v[0] + fr.lm_v[1];
    cos_i = std::abs(dl[fr.axis_n]);
  } else {
    float q[3], n[3], u, v;
    for (int i = 0; i < 3; ++i) q[i] = o[i] + t_hit * dl[i];
    detail::faceUv(p, face, q, u, v);
    detail::faceNormal(p, face, q, n);
    tx = u * fr.su + fr.ou;
    ty = fr.ov - v * fr.sv;
    cos_i = std::abs(n[0] * dl[0] + n[1] * dl[1] + n[2] * dl[2]);
    lx = ly = 0.f;
    if (fr.lightmap >= 0) {
      const detail::LightmapRecord& lm = world_.lightmaps[fr.lightmap];
      lx = u * lm.su - 0.5f;
      ly = v * lm.sv - 0.5f;
    }
  }

  float albedo = fr.albedo;
  if (fr.texture >= 0) {
    const float minor = t_hit * pixel_angle;
    const float major = minor / std::max(cos_i, 0.02f);
    const float footprint = std::max(minor, major * (1.f / kMaxAnisotropy)) * std::max(fr.su, fr.sv);
    const float lod = footprint > 1.f ? fastLog2(footprint) : 0.f;
    albedo *= to_linear_[static_cast<int>(world_.textures[fr.texture].sample(tx, ty, lod) * 4.f)];
  }
  float irradiance;
  if (fr.lightmap >= 0) {
    const detail::LightmapRecord& lm = world_.lightmaps[fr.lightmap];
    const float x = std::clamp(lx, 0.f, static_cast<float>(lm.w - 1));
    const float y = std::clamp(ly, 0.f, static_cast<float>(lm.h - 1));
    const int x0 = std::min(static_cast<int>(x), lm.w - 2), y0 = std::min(static_cast<int>(y), lm.h - 2);
    const float fx = x - static_cast<float>(x0), fy = y - static_cast<float>(y0);
    const float* c = &world_.lightmap_values[lm.offset + static_cast<std::size_t>(y0) * lm.w + x0];
    const float a = c[0] + fx * (c[1] - c[0]);
    const float b = c[lm.w] + fx * (c[lm.w + 1] - c[lm.w]);
    irradiance = a + fy * (b - a);
  } else {
    float q[3], n[3], nw[3];
    for (int i = 0; i < 3; ++i) q[i] = o[i] + t_hit * dl[i];
    detail::faceNormal(p, face, q, n);
    p.toWorld(n, nw);
    irradiance = world_.unlitIrradiance(Vec3(nw[0], nw[1], nw[2]));
  }
  return albedo * irradiance + fr.emission;
}

}  // namespace mcslam::sim
