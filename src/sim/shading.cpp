// Shading of surface hits: texture (mip level from the ray footprint) x baked irradiance + emission. One pixel at a
// time for any surface, or four neighbouring pixels at once when they all see the same light-mapped box face
// (most of every image: walls, floors, furniture), where the arithmetic runs on four lanes and the texture level
// is chosen once for the four.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "frame_context.hpp"

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

// Texture filter footprint in texels of a hit at distance t seen under pixel_angle with incidence cosine cos_i.
// T: float or f4.
template <class T>
T footprint(T t, T pixel_angle, T cos_i, const FaceRecord& fr) {
  const T minor = t * pixel_angle;
  const T major = minor / vmax(cos_i, 0.02f);
  return vmax(minor, major * (1.f / kMaxAnisotropy)) * std::max(fr.su, fr.sv);
}

inline float lodOf(float footprint) { return footprint > 1.f ? fastLog2(footprint) : 0.f; }

// Face coordinates of a box hit: texture (tx, ty), light-map cell (lx, ly), and the cosine of incidence.
template <class T>
struct FaceCoords {
  T tx, ty, lx, ly, cos_i;
};

template <class T>
FaceCoords<T> boxFaceCoords(const FaceRecord& fr, const float o[3], T t, const T dl[3]) {
  const T qa = o[fr.axis_u] + t * dl[fr.axis_u], qb = o[fr.axis_v] + t * dl[fr.axis_v];
  return {qa * fr.tex_u[0] + fr.tex_u[1], qb * fr.tex_v[0] + fr.tex_v[1], qa * fr.lm_u[0] + fr.lm_u[1],
          qb * fr.lm_v[0] + fr.lm_v[1], vabs(dl[fr.axis_n])};
}

// Corners i, i + 1, i + w, i + w + 1 of base.
inline void cellCorners(const float* base, int i, int w, float& c00, float& c10, float& c01, float& c11) {
  c00 = base[i];
  c10 = base[i + 1];
  c01 = base[i + w];
  c11 = base[i + w + 1];
}
// The same per lane. Light-map cells (tens of centimetres) are much larger than a pixel's footprint, so the four
// lanes nearly always share one cell: then four loads instead of sixteen.
inline void cellCorners(const float* base, i4 i, int w, f4& c00, f4& c10, f4& c01, f4& c11) {
  if (!any(i != i[0])) {
    float a, b, c, d;
    cellCorners(base, i[0], w, a, b, c, d);
    c00 = splat(a);
    c10 = splat(b);
    c01 = splat(c);
    c11 = splat(d);
    return;
  }
  c00 = gather(base, i);
  c10 = gather(base, i + 1);
  c01 = gather(base, i + w);
  c11 = gather(base, i + w + 1);
}

// Bilinear irradiance at light-map cell coordinates (lx, ly). F: float, or f4 for four points of one face.
template <class F>
F lightmapIrradiance(const detail::WorldData& w, const detail::LightmapRecord& lm, F lx, F ly) {
  const F x = vmin(vmax(lx, 0.f), static_cast<float>(lm.w - 1));
  const F y = vmin(vmax(ly, 0.f), static_cast<float>(lm.h - 1));
  const auto x0 = vmin(toInt(x), lm.w - 2), y0 = vmin(toInt(y), lm.h - 2);
  const F fx = x - toFloat(x0), fy = y - toFloat(y0);
  const float* c = &w.lightmap_values[lm.offset];
  const auto i = y0 * lm.w + x0;
  F c00, c10, c01, c11;
  cellCorners(c, i, lm.w, c00, c10, c01, c11);
  const F a = c00 + fx * (c10 - c00);
  const F b = c01 + fx * (c11 - c01);
  return a + fy * (b - a);
}

}  // namespace

float FrameContext::shade(uint32_t k, float t_hit, const float d[3], float pixel_angle) const {
  const int pi = keyPrim(k), face = keyFace(k);
  const Prim& p = prim(pi);
  const FaceRecord& fr = world_.faces[p.face0 + face];
  const float* o = localOrigin(pi);
  float dl[3];
  p.toLocal(d, dl);
  FaceCoords<float> c;
  if (p.type == detail::PrimType::Box) {
    c = boxFaceCoords(fr, o, t_hit, dl);
  } else {
    float q[3], n[3], u, v;
    for (int i = 0; i < 3; ++i) q[i] = o[i] + t_hit * dl[i];
    detail::faceUv(p, face, q, u, v);
    detail::faceNormal(p, face, q, n);
    c.tx = u * fr.su + fr.ou;
    c.ty = fr.ov - v * fr.sv;
    c.cos_i = std::abs(n[0] * dl[0] + n[1] * dl[1] + n[2] * dl[2]);
    c.lx = c.ly = 0.f;
    if (fr.lightmap >= 0) {
      const detail::LightmapRecord& lm = world_.lightmaps[fr.lightmap];
      c.lx = u * lm.su - 0.5f;
      c.ly = v * lm.sv - 0.5f;
    }
  }

  float albedo = fr.albedo;
  if (fr.texture >= 0) {
    const float lod = lodOf(footprint(t_hit, pixel_angle, c.cos_i, fr));
    albedo *= to_linear_[static_cast<int>(world_.textures[fr.texture].sample(c.tx, c.ty, lod) * 4.f)];
  }
  float irradiance;
  if (fr.lightmap >= 0) {
    irradiance = lightmapIrradiance(world_, world_.lightmaps[fr.lightmap], c.lx, c.ly);
  } else {
    float q[3], n[3], nw[3];
    for (int i = 0; i < 3; ++i) q[i] = o[i] + t_hit * dl[i];
    detail::faceNormal(p, face, q, n);
    p.toWorld(n, nw);
    irradiance = world_.unlitIrradiance(Vec3(nw[0], nw[1], nw[2]));
  }
  return albedo * irradiance + fr.emission;
}

bool FrameContext::quadShadable(uint32_t k) const {
  const Prim& p = prim(keyPrim(k));
  return p.type == detail::PrimType::Box && world_.faces[p.face0 + keyFace(k)].lightmap >= 0;
}

f4 FrameContext::shadeQuad(uint32_t k, f4 t_hit, const f4 b[3], f4 pixel_angle) const {
  const int pi = keyPrim(k);
  const Prim& p = prim(pi);
  const FaceRecord& fr = world_.faces[p.face0 + keyFace(k)];
  f4 d[3], dl[3];
  rotate(b, d);
  p.toLocal(d, dl);
  const FaceCoords<f4> c = boxFaceCoords(fr, localOrigin(pi), t_hit, dl);
  f4 albedo = splat(fr.albedo);
  if (fr.texture >= 0) {
    const float lod = lodOf(0.25f * sum(footprint(t_hit, pixel_angle, c.cos_i, fr)));
    const i4 grey = toInt(world_.textures[fr.texture].sample4(c.tx, c.ty, lod) * 4.f);
    albedo *= lanes([&](int l) { return to_linear_[grey[l]]; });
  }
  return albedo * lightmapIrradiance(world_, world_.lightmaps[fr.lightmap], c.lx, c.ly) + fr.emission;
}

}  // namespace mcslam::sim
