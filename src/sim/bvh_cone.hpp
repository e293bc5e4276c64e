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
    const int i = stack[--top];
    const BvhNode& n = nodes_[i];
    if (!sphereMeetsCone(apex, axis, cos_a, sin_a, spheres_[i].c, spheres_[i].r)) continue;
    if (n.count > 0) {
      for (int k = 0; k < n.count; ++k) {
        const int idx = order_[n.first + k];
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
