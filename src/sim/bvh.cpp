#include "bvh.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "primitive.hpp"

namespace mcslam::sim::detail {

namespace {

constexpr int kLeafSize = 2;

void growBounds(const Prim& p, float lo[3], float hi[3]) {
  float a[3], b[3];
  p.aabb(a, b);
  for (int k = 0; k < 3; ++k) {
    lo[k] = std::min(lo[k], a[k]);
    hi[k] = std::max(hi[k], b[k]);
  }
}

// Slab test of a node box; entry distance in t_near.
bool hitsBox(const BvhNode& n, const float O[3], const float inv[3], float tmax, float& t_near) {
  float t0 = 0.f, t1 = tmax;
  for (int k = 0; k < 3; ++k) {
    float a = (n.lo[k] - O[k]) * inv[k], b = (n.hi[k] - O[k]) * inv[k];
    if (a > b) std::swap(a, b);
    if (!(a <= b)) {  // NaN: the ray is parallel and on the slab plane; inside if O is within the slab
      if (O[k] < n.lo[k] || O[k] > n.hi[k]) return false;
      continue;
    }
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    if (t0 > t1) return false;
  }
  t_near = t0;
  return true;
}

}  // namespace

void Bvh::build(const std::vector<Prim>& prims) {
  nodes_.clear();
  order_.resize(prims.size());
  std::iota(order_.begin(), order_.end(), 0);
  if (prims.empty()) return;
  std::vector<float> centroids(prims.size() * 3);
  for (std::size_t i = 0; i < prims.size(); ++i) {
    float lo[3], hi[3];
    prims[i].aabb(lo, hi);
    for (int k = 0; k < 3; ++k) centroids[3 * i + k] = 0.5f * (lo[k] + hi[k]);
  }
  nodes_.reserve(2 * prims.size());
  nodes_.emplace_back();
  buildRange(prims, centroids, 0, 0, static_cast<int>(prims.size()));
  spheres_.resize(nodes_.size());
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    const BvhNode& n = nodes_[i];
    BvhSphere& b = spheres_[i];
    for (int k = 0; k < 3; ++k) b.c[k] = 0.5f * (n.lo[k] + n.hi[k]);
    const float e0 = n.hi[0] - n.lo[0], e1 = n.hi[1] - n.lo[1], e2 = n.hi[2] - n.lo[2];
    b.r = 0.5f * std::sqrt(e0 * e0 + e1 * e1 + e2 * e2);
  }
}

// Fills node `self` for order_[begin, end); median split along the widest centroid axis. Children are allocated
// side by side (left, left + 1).
void Bvh::buildRange(const std::vector<Prim>& prims, std::vector<float>& centroids, int self, int begin, int end) {
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  float clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int i = begin; i < end; ++i) {
    growBounds(prims[order_[i]], lo, hi);
    for (int k = 0; k < 3; ++k) {
      clo[k] = std::min(clo[k], centroids[3 * order_[i] + k]);
      chi[k] = std::max(chi[k], centroids[3 * order_[i] + k]);
    }
  }
  for (int k = 0; k < 3; ++k) {
    nodes_[self].lo[k] = lo[k];
    nodes_[self].hi[k] = hi[k];
  }
  if (end - begin <= kLeafSize) {
    nodes_[self].first = begin;
    nodes_[self].count = end - begin;
    return;
  }
  int axis = 0;
  for (int k = 1; k < 3; ++k) {
    if (chi[k] - clo[k] > chi[axis] - clo[axis]) axis = k;
  }
  const int mid = (begin + end) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end, [&](int a, int b) {
    const float ca = centroids[3 * a + axis], cb = centroids[3 * b + axis];
    return ca < cb || (ca == cb && a < b);  // a total order: the tree does not depend on the library's sort
  });
  const int left = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  nodes_.emplace_back();
  nodes_[self].first = left;
  nodes_[self].count = 0;
  buildRange(prims, centroids, left, begin, mid);
  buildRange(prims, centroids, left + 1, mid, end);
}

int Bvh::closest(const std::vector<Prim>& prims, const float O[3], const float D[3], float tmin, float tmax, float& t,
                 int& face) const {
  if (nodes_.empty()) return -1;
  const float inv[3] = {1.f / D[0], 1.f / D[1], 1.f / D[2]};
  int best = -1;
  float best_t = tmax;
  int stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BvhNode& n = nodes_[stack[--top]];
    float t_near;
    if (!hitsBox(n, O, inv, best_t, t_near)) continue;
    if (n.count > 0) {
      for (int i = 0; i < n.count; ++i) {
        const int idx = order_[n.first + i];
        const Prim& p = prims[idx];
        float o[3], d[3], th;
        int f;
        p.localOrigin(O, o);
        p.toLocal(D, d);
        if (intersectLocal(p, o, d, tmin, best_t, th, f)) {
          best_t = th;
          best = idx;
          face = f;
        }
      }
    } else {
      stack[top++] = n.first;
      stack[top++] = n.first + 1;
    }
  }
  if (best >= 0) t = best_t;
  return best;
}

bool Bvh::occluded(const std::vector<Prim>& prims, const float O[3], const float D[3], float tmin, float tmax) const {
  if (nodes_.empty()) return false;
  const float inv[3] = {1.f / D[0], 1.f / D[1], 1.f / D[2]};
  int stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BvhNode& n = nodes_[stack[--top]];
    float t_near;
    if (!hitsBox(n, O, inv, tmax, t_near)) continue;
    if (n.count > 0) {
      for (int i = 0; i < n.count; ++i) {
        const Prim& p = prims[order_[n.first + i]];
        float o[3], d[3], th;
        int f;
        p.localOrigin(O, o);
        p.toLocal(D, d);
        if (intersectLocal(p, o, d, tmin, tmax, th, f)) return true;
      }
    } else {
      stack[top++] = n.first;
      stack[top++] = n.first + 1;
    }
  }
  return false;
}

}  // namespace mcslam::sim::detail
