#pragma once
// Ray tests and surface parametrisation of the two primitive shapes, in float for the per-pixel path.
// A ray is tested in the primitive's own frame: o = R (O - c) is computed once per camera, d = R D per ray.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "mcslam/core/se3.hpp"

namespace mcslam::sim::detail {

enum class PrimType : uint8_t { Box = 0, Cylinder = 1 };

struct Prim {
  float R[9];      // world -> local rotation, row-major (rows are the local axes in the world)
  float c[3];      // centre in the world
  float h[3];      // box: half extents; cylinder: radius, radius, half height
  float radius;    // bounding sphere around c
  uint32_t face0;  // first face record
  PrimType type;
  bool aligned;  // R is the identity: rays need no rotation (walls, floors, most furniture)

  static Prim box(const SE3& T_w_o, const Vec3& half, uint32_t face0);
  static Prim cylinder(const SE3& T_w_o, double r, double half_height, uint32_t face0);
  int faceCount() const { return type == PrimType::Box ? 6 : 3; }
  SE3 pose() const;  // T_w_o
  void aabb(float lo[3], float hi[3]) const;

  // T: float, or a four-lane vector (f4) of directions.
  template <class T>
  void toLocal(const T v[3], T out[3]) const {
    if (aligned) {
      out[0] = v[0];
      out[1] = v[1];
      out[2] = v[2];
      return;
    }
    out[0] = R[0] * v[0] + R[1] * v[1] + R[2] * v[2];
    out[1] = R[3] * v[0] + R[4] * v[1] + R[5] * v[2];
    out[2] = R[6] * v[0] + R[7] * v[1] + R[8] * v[2];
  }
  void localOrigin(const float O[3], float out[3]) const {
    const float v[3] = {O[0] - c[0], O[1] - c[1], O[2] - c[2]};
    toLocal(v, out);
  }
  // World direction of a local vector.
  void toWorld(const float v[3], float out[3]) const {
    if (aligned) {
      out[0] = v[0];
      out[1] = v[1];
      out[2] = v[2];
      return;
    }
    out[0] = R[0] * v[0] + R[3] * v[1] + R[6] * v[2];
    out[1] = R[1] * v[0] + R[4] * v[1] + R[7] * v[2];
    out[2] = R[2] * v[0] + R[5] * v[1] + R[8] * v[2];
  }
};

constexpr float kRayEpsilon = 1e-4f;  // hits closer than this are ignored (self-intersection)

// Slab test of a box with half extents h for the local ray (o, 1/d): entry t in (tmin, tmax) and the face.
// Branch-free; directions are never exactly axis-parallel (see safeInverse), so no NaN arises.
inline bool intersectBox(const float h[3], const float o[3], const float inv[3], float tmin, float tmax, float& t_hit,
                         int& face) {
  const float ax = (-h[0] - o[0]) * inv[0], bx = (h[0] - o[0]) * inv[0];
  const float ay = (-h[1] - o[1]) * inv[1], by = (h[1] - o[1]) * inv[1];
  const float az = (-h[2] - o[2]) * inv[2], bz = (h[2] - o[2]) * inv[2];
  const float nx = std::min(ax, bx), ny = std::min(ay, by), nz = std::min(az, bz);
  const float t_enter = std::max(nx, std::max(ny, nz));
  const float t_exit = std::min(std::max(ax, bx), std::min(std::max(ay, by), std::max(az, bz)));
  if (!(t_enter <= t_exit && t_enter > tmin && t_enter < tmax)) return false;
  t_hit = t_enter;
  const int axis = t_enter == nx ? 0 : (t_enter == ny ? 1 : 2);
  face = axis * 2 + (inv[axis] < 0 ? 1 : 0);  // travelling towards -axis enters through the + face
  return true;
}

// 1/d with exact zeros nudged to a tiny value: parallel rays then give huge finite slab distances.
inline void safeInverse(const float d[3], float inv[3]) {
  for (int k = 0; k < 3; ++k) inv[k] = 1.f / (d[k] != 0.f ? d[k] : 1e-30f);
}

// Local ray (o, d): nearest entry t in (tmin, tmax) and the face hit. Rays starting inside see nothing.
inline bool intersectLocal(const Prim& p, const float o[3], const float d[3], float tmin, float tmax, float& t_hit,
                           int& face) {
  if (p.type == PrimType::Box) {
    float inv[3];
    safeInverse(d, inv);
    return intersectBox(p.h, o, inv, tmin, tmax, t_hit, face);
  }
  // Cylinder along local z: radius h[0], half height h[2].
  const float r = p.h[0], hz = p.h[2];
  float best = tmax;
  int best_face = -1;
  const float a = d[0] * d[0] + d[1] * d[1];
  const float cc = o[0] * o[0] + o[1] * o[1] - r * r;
  if (a > 1e-12f && cc > 0.f) {
    const float b = o[0] * d[0] + o[1] * d[1];
    const float disc = b * b - a * cc;
    if (disc >= 0.f) {
      const float t = (-b - std::sqrt(disc)) / a;
      const float z = o[2] + t * d[2];
      if (t > tmin && t < best && std::abs(z) <= hz) {
        best = t;
        best_face = 0;
      }
    }
  }
  if (d[2] != 0.f) {
    const bool from_top = o[2] > hz;
    if (from_top || o[2] < -hz) {
      const float t = ((from_top ? hz : -hz) - o[2]) / d[2];
      if (t > tmin && t < best) {
        const float x = o[0] + t * d[0], y = o[1] + t * d[1];
        if (x * x + y * y <= r * r) {
          best = t;
          best_face = from_top ? 2 : 1;
        }
      }
    }
  }
  if (best_face < 0) return false;
  t_hit = best;
  face = best_face;
  return true;
}

// Face coordinates in metres of a local point on face `face`, laid out so that a viewer facing the face sees u
// to the right and v up (+z for side faces, +y for the caps of boxes).
inline void faceUv(const Prim& p, int face, const float q[3], float& u, float& v) {
  if (p.type == PrimType::Box) {
    const int k = face >> 1;
    const float s = (face & 1) ? 1.f : -1.f;
    switch (k) {
      case 0:
        u = s * q[1] + p.h[1];
        v = q[2] + p.h[2];
        return;
      case 1:
        u = -s * q[0] + p.h[0];
        v = q[2] + p.h[2];
        return;
      default:
        u = s * q[0] + p.h[0];
        v = q[1] + p.h[1];
        return;
    }
  }
  const float r = p.h[0];
  if (face == 0) {
    u = r * (std::atan2(q[1], q[0]) + static_cast<float>(M_PI));
    v = q[2] + p.h[2];
  } else {
    u = (face == 2 ? q[0] : -q[0]) + r;
    v = q[1] + r;
  }
}

// Extent of a face in its (u, v) metres.
inline void faceSize(const Prim& p, int face, float& w, float& h) {
  if (p.type == PrimType::Box) {
    const int k = face >> 1;
    const int a = k == 0 ? 1 : 0, b = k == 2 ? 1 : 2;
    w = 2 * p.h[a];
    h = 2 * p.h[b];
    return;
  }
  const float r = p.h[0];
  if (face == 0) {
    w = static_cast<float>(2 * M_PI) * r;
    h = 2 * p.h[2];
  } else {
    w = h = 2 * r;
  }
}

// Local point of face coordinates (inverse of faceUv), on the surface.
inline void facePoint(const Prim& p, int face, float u, float v, float q[3]) {
  if (p.type == PrimType::Box) {
    const int k = face >> 1;
    const float s = (face & 1) ? 1.f : -1.f;
    switch (k) {
      case 0:
        q[0] = s * p.h[0];
        q[1] = s * (u - p.h[1]);
        q[2] = v - p.h[2];
        return;
      case 1:
        q[1] = s * p.h[1];
        q[0] = -s * (u - p.h[0]);
        q[2] = v - p.h[2];
        return;
      default:
        q[2] = s * p.h[2];
        q[0] = s * (u - p.h[0]);
        q[1] = v - p.h[1];
        return;
    }
  }
  const float r = p.h[0];
  if (face == 0) {
    const float a = u / r - static_cast<float>(M_PI);
    q[0] = r * std::cos(a);
    q[1] = r * std::sin(a);
    q[2] = v - p.h[2];
  } else {
    q[0] = (face == 2 ? 1.f : -1.f) * (u - r);
    q[1] = v - r;
    q[2] = face == 2 ? p.h[2] : -p.h[2];
  }
}

// Outward unit normal in the local frame at local point q of face `face`.
inline void faceNormal(const Prim& p, int face, const float q[3], float n[3]) {
  n[0] = n[1] = n[2] = 0.f;
  if (p.type == PrimType::Box) {
    n[face >> 1] = (face & 1) ? 1.f : -1.f;
    return;
  }
  if (face == 0) {
    const float inv = 1.0f / std::sqrt(q[0] * q[0] + q[1] * q[1] + 1e-20f);
    n[0] = q[0] * inv;
    n[1] = q[1] * inv;
  } else {
    n[2] = face == 2 ? 1.f : -1.f;
  }
}

}  // namespace mcslam::sim::detail
