#pragma once
// Template body of Bvh::cone, included by its users (it needs the full Prim).
#include <algorithm>
#include <cmath>

#include "bvh.hpp"
#include "primitive.hpp"

namespace mcslam::sim::detail {

template <class Visit>
void Bvh::cone(const std::vector<Prim>& prims, const float apex[3], const float axis[3], float cos_a, float sin_a,
               Visit&& visit) const {
  if (nodes_.empty()) return;
  int stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BvhNode& n = nodes_[stack[--top]];
    const float c[3] = {0.5f * (n.lo[0] + n.hi[0]), 0.5f * (n.lo[1] + n.hi[1]), 0.5f * (n.lo[2] + n.hi[2])};
    const float e0 = n.hi[0] - n.lo[0], e1 = n.hi[1] - n.lo[1], e2 = n.hi[2] - n.lo[2];
    const float r = 0.5f * std::sqrt(e0 * e0 + e1 * e1 + e2 * e2);
    if (!sphereMeetsCone(apex, axis, cos_a, sin_a, c, r)) continue;
    if (n.count > 0) {
      for (int i = 0; i < n.count; ++i) {
        const int idx = order_[n.first + i];
        const Prim& p = prims[idx];
        if (sphereMeetsCone(apex, axis, cos_a, sin_a, p.c, p.radius)) visit(idx);
      }
    } else {
      stack[top++] = n.first;
      stack[top++] = n.first + 1;
    }
  }
}

}  // namespace mcslam::sim::detail
