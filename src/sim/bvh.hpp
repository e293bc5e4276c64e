#pragma once
// Bounding-volume hierarchy over the static primitives: closest-hit and any-hit ray queries (building, baking,
// World::intersect) and cone queries (the renderer's per-tile candidate lists).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace mcslam::sim::detail {

struct Prim;

struct BvhNode {
  float lo[3], hi[3];
  int32_t first = 0;  // leaf: first index into Bvh::order; inner: index of the left child (right = left + 1)
  int32_t count = 0;  // > 0 for leaves
};

// Bounding sphere of a node's box, for cone queries (computed once at build instead of at every visit).
struct BvhSphere {
  float c[3], r;
};

class Bvh {
 public:
  void build(const std::vector<Prim>& prims);
  bool empty() const { return nodes_.empty(); }

  // Closest hit along O + t D (D unit) with t in (tmin, tmax); returns the primitive index or -1.
  int closest(const std::vector<Prim>& prims, const float O[3], const float D[3], float tmin, float tmax, float& t,
              int& face) const;
  // True when anything blocks O + t D for t in (tmin, tmax).
  bool occluded(const std::vector<Prim>& prims, const float O[3], const float D[3], float tmin, float tmax) const;

  // Calls visit(prim_index) for every primitive whose bounding sphere meets the cone (apex, unit axis,
  // half-angle given by its cosine and sine).
  template <class Visit>
  void cone(const std::vector<Prim>& prims, const float apex[3], const float axis[3], float cos_a, float sin_a,
            Visit&& visit) const;

  // Calls visit(prim_index) for every primitive whose bounding box contains p.
  template <class Visit>
  void point(const std::vector<Prim>& prims, const float p[3], Visit&& visit) const {
    if (nodes_.empty()) return;
    int stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const BvhNode& n = nodes_[stack[--top]];
      if (p[0] < n.lo[0] || p[1] < n.lo[1] || p[2] < n.lo[2] || p[0] > n.hi[0] || p[1] > n.hi[1] || p[2] > n.hi[2])
        continue;
      if (n.count > 0) {
        for (int i = 0; i < n.count; ++i) visit(order_[n.first + i]);
      } else {
        stack[top++] = n.first;
        stack[top++] = n.first + 1;
      }
    }
  }

  const std::vector<BvhNode>& nodes() const { return nodes_; }
  const std::vector<int32_t>& order() const { return order_; }

 private:
  void buildRange(const std::vector<Prim>& prims, std::vector<float>& centroids, int self, int begin, int end);
  std::vector<BvhNode> nodes_;
  std::vector<BvhSphere> spheres_;  // per node
  std::vector<int32_t> order_;
};

// Sphere (centre c, radius r) against a cone; conservative (never misses an intersecting sphere).
inline bool sphereMeetsCone(const float apex[3], const float axis[3], float cos_a, float sin_a, const float c[3],
                            float r) {
  const float v0 = c[0] - apex[0], v1 = c[1] - apex[1], v2 = c[2] - apex[2];
  const float d2 = v0 * v0 + v1 * v1 + v2 * v2;
  if (d2 <= r * r) return true;
  const float d = std::sqrt(d2);
  const float along = v0 * axis[0] + v1 * axis[1] + v2 * axis[2];
  // Angle of the centre from the axis must not exceed the cone angle plus the sphere's angular radius.
  const float sin_b = r / d, cos_b = std::sqrt(std::max(0.f, 1.f - sin_b * sin_b));
  const float cos_sum = cos_a * cos_b - sin_a * sin_b;   // cos(a + b)
  if (sin_a * cos_b + cos_a * sin_b < 0.f) return true;  // a + b beyond pi
  return along >= d * cos_sum;
}

}  // namespace mcslam::sim::detail
