#include "frame_context.hpp"

#include <algorithm>
#include <cmath>

#include "bvh_cone.hpp"

namespace mcslam::sim {

using detail::FaceRecord;
using detail::Prim;

namespace {

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

}  // namespace mcslam::sim
