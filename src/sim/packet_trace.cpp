#include "packet_trace.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace mcslam::sim {

namespace {

// Cylinders and turned boxes (rare): one lane at a time. Returns whether a lane's nearest hit changed.
__attribute__((noinline)) bool slowTest(const FrameContext& ctx, const Candidate& c, int j, const RayPacket& rays,
                                        f4& best, i4& best_key, i4& best_c) {
  const detail::Prim& p = ctx.prim(static_cast<int>(c.prim));
  bool changed = false;
  for (int l = 0; l < 4; ++l) {
    if (!(best[l] > 0.f)) continue;
    const float d[3] = {rays.d[0][l], rays.d[1][l], rays.d[2][l]};
    float dl[3], th;
    int face;
    p.toLocal(d, dl);
    if (detail::intersectLocal(p, c.o, dl, detail::kRayEpsilon, best[l], th, face)) {
      best[l] = th;
      best_c[l] = j;
      best_key[l] = static_cast<int32_t>(makeKey(static_cast<int>(c.prim), face));
      changed = true;
    }
  }
  return changed;
}

}  // namespace

void tracePacket(const FrameContext& ctx, const std::vector<Candidate>& cands, const RayPacket& rays, int& hint,
                 uint32_t keys[4], float t[4]) {
  f4 inv[3];
  for (int k = 0; k < 3; ++k) inv[k] = 1.f / (rays.d[k] != 0.f ? rays.d[k] : splat(1e-30f));
  // Padding lanes start with best = 0: nothing can be nearer, so they never hit and never block early exit.
  f4 best = rays.active != 0 ? splat(INFINITY) : splat(0.f);
  i4 best_key = {0, 0, 0, 0};
  i4 best_c = {-1, -1, -1, -1};
  float worst = hmax(best);  // largest best over the lanes: candidates beyond it cannot matter
  const f4 eps = splat(detail::kRayEpsilon);
  // Face entered through along each axis: travelling towards -axis enters through the + face (odd index).
  const i4 face_x = inv[0] < 0.f ? i4{1, 1, 1, 1} : i4{0, 0, 0, 0};
  const i4 face_y = inv[1] < 0.f ? i4{3, 3, 3, 3} : i4{2, 2, 2, 2};
  const i4 face_z = inv[2] < 0.f ? i4{5, 5, 5, 5} : i4{4, 4, 4, 4};

  // Inlined, so that the packet's state stays in registers (a called lambda would pass it through memory).
  auto test = [&](int j) __attribute__((always_inline)) {
    const Candidate& c = cands[j];
    if (!c.fast) {
      if (slowTest(ctx, c, j, rays, best, best_key, best_c)) worst = hmax(best);
      return;
    }
    const f4 ax = (-c.h[0] - c.o[0]) * inv[0], bx = (c.h[0] - c.o[0]) * inv[0];
    const f4 ay = (-c.h[1] - c.o[1]) * inv[1], by = (c.h[1] - c.o[1]) * inv[1];
    const f4 az = (-c.h[2] - c.o[2]) * inv[2], bz = (c.h[2] - c.o[2]) * inv[2];
    const f4 nx = vmin(ax, bx), ny = vmin(ay, by), nz = vmin(az, bz);
    const f4 tn = vmax(nx, vmax(ny, nz));
    const f4 tf = vmin(vmax(ax, bx), vmin(vmax(ay, by), vmax(az, bz)));
    const i4 hit = (tn <= tf) & (tn > eps) & (tn < best);
    if (!any(hit)) return;
    const int32_t base = static_cast<int32_t>(makeKey(static_cast<int>(c.prim), 0));
    const i4 face = tn == nx ? face_x : (tn == ny ? face_y : face_z);
    best = hit ? tn : best;
    best_key = hit ? (face | base) : best_key;
    best_c = hit ? i4{j, j, j, j} : best_c;
    worst = hmax(best);
  };

  const int n = static_cast<int>(cands.size());
  if (hint >= 0 && hint < n - 1) test(hint);
  for (int j = 0; j < n; ++j) {
    if (cands[j].near >= worst) break;  // the sentinel always stops here
    if (j != hint) test(j);
  }

  hint = -1;
  for (int l = 0; l < 4 && hint < 0; ++l) hint = best_c[l];
  std::memcpy(keys, &best_key, sizeof best_key);
  store4(t, best_c >= 0 ? best : splat(0.f));
}

}  // namespace mcslam::sim
