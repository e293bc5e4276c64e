#include "primitive.hpp"

#include <algorithm>

namespace mcslam::sim::detail {

namespace {
void setPose(Prim& p, const SE3& T_w_o) {
  const Mat3 R_o_w = T_w_o.R.transpose();
  p.aligned = R_o_w.isIdentity(0.0);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) p.R[3 * r + c] = static_cast<float>(R_o_w(r, c));
    p.c[r] = static_cast<float>(T_w_o.t[r]);
  }
}
}  // namespace

Prim Prim::box(const SE3& T_w_o, const Vec3& half, uint32_t face0) {
  Prim p{};
  setPose(p, T_w_o);
  for (int k = 0; k < 3; ++k) p.h[k] = static_cast<float>(half[k]);
  p.radius = static_cast<float>(half.norm());
  p.face0 = face0;
  p.type = PrimType::Box;
  return p;
}

Prim Prim::cylinder(const SE3& T_w_o, double r, double half_height, uint32_t face0) {
  Prim p{};
  setPose(p, T_w_o);
  p.h[0] = p.h[1] = static_cast<float>(r);
  p.h[2] = static_cast<float>(half_height);
  p.radius = static_cast<float>(std::sqrt(r * r + half_height * half_height));
  p.face0 = face0;
  p.type = PrimType::Cylinder;
  return p;
}

SE3 Prim::pose() const {
  Mat3 R_o_w;
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) R_o_w(r, k) = R[3 * r + k];
  }
  SE3 T(R_o_w.transpose(), Vec3(c[0], c[1], c[2]));
  T.normalize();
  return T;
}

void Prim::aabb(float lo[3], float hi[3]) const {
  // Extent along world axis j = sum over local axes of |R_kj| * h_k (box; a cylinder is inside its box).
  for (int j = 0; j < 3; ++j) {
    const float e = std::abs(R[j]) * h[0] + std::abs(R[3 + j]) * h[1] + std::abs(R[6 + j]) * h[2];
    lo[j] = c[j] - e;
    hi[j] = c[j] + e;
  }
}

}  // namespace mcslam::sim::detail
