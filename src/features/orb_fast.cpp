#include "orb_fast.hpp"

#include <algorithm>
#include <array>
#include <cstddef>

#include "orb_simd.hpp"

namespace mcslam::orb_detail {
namespace {

// The 16-pixel Bresenham circle of radius 3, clockwise from the top.
constexpr int kCircleX[16] = {0, 1, 2, 3, 3, 3, 2, 1, 0, -1, -2, -3, -3, -3, -2, -1};
constexpr int kCircleY[16] = {-3, -3, -2, -1, 0, 1, 2, 3, 3, 3, 2, 1, 0, -1, -2, -3};

// max over the 16 arcs of 9 contiguous pixels of the smallest value on the arc.
template <class V>
V bestArcMinimum(const V (&d)[16]) {
  V m2[16], m4[16];
  for (int k = 0; k < 16; ++k) m2[k] = min(d[k], d[(k + 1) & 15]);
  for (int k = 0; k < 16; ++k) m4[k] = min(m2[k], m2[(k + 2) & 15]);
  V best = min(min(m4[0], m4[4]), d[8]);
  for (int k = 1; k < 16; ++k) best = max(best, min(min(m4[k], m4[(k + 4) & 15]), d[(k + 8) & 15]));
  return best;
}

template <class V>
int scoreRow(const uint8_t* image, int stride, int y, int x0, int x1, int threshold, uint8_t* out) {
  std::ptrdiff_t offsets[16];
  for (int k = 0; k < 16; ++k) offsets[k] = static_cast<std::ptrdiff_t>(kCircleY[k]) * stride + kCircleX[k];
  const V t = V::splat(static_cast<uint8_t>(std::clamp(threshold, 1, 254)));
  const uint8_t* row = image + static_cast<std::ptrdiff_t>(y) * stride;
  int corners = 0;
  for (int x = x0; x < x1; x += 16) {
    const uint8_t* p = row + x;
    const V c = V::load(p);
    const V bright_limit = adds(c, t);
    const V dark_limit = subs(c, t);
    // Any 9-arc covers two neighbouring compass points (0, 4, 8, 12): reject the rest cheaply.
    const V n = V::load(p + offsets[0]), e = V::load(p + offsets[4]);
    const V s = V::load(p + offsets[8]), w = V::load(p + offsets[12]);
    const V bn = subs(n, bright_limit), be = subs(e, bright_limit);
    const V bs = subs(s, bright_limit), bw = subs(w, bright_limit);
    const V dn = subs(dark_limit, n), de = subs(dark_limit, e);
    const V ds = subs(dark_limit, s), dw = subs(dark_limit, w);
    const V bright_pair = max(max(min(bn, be), min(be, bs)), max(min(bs, bw), min(bw, bn)));
    const V dark_pair = max(max(min(dn, de), min(de, ds)), max(min(ds, dw), min(dw, dn)));
    const int n_out = std::min(16, x1 - x);
    uint8_t scores[16];
    if (!max(bright_pair, dark_pair).anyNonZero()) {
      std::fill(out + (x - x0), out + (x - x0) + n_out, uint8_t{0});
      continue;
    }
    V brighter[16], darker[16];
    for (int k = 0; k < 16; ++k) {
      const V pk = V::load(p + offsets[k]);
      brighter[k] = subs(pk, c);
      darker[k] = subs(c, pk);
    }
    const V score = keepAbove(max(bestArcMinimum(brighter), bestArcMinimum(darker)), t);
    score.store(scores);
    for (int i = 0; i < n_out; ++i) corners += scores[i] != 0;
    std::copy(scores, scores + n_out, out + (x - x0));
  }
  return corners;
}

}  // namespace

bool fastHasNativeSimd() {
#if defined(MCSLAM_ORB_HAVE_NATIVE)
  return true;
#else
  return false;
#endif
}

int fastScoreRow(const uint8_t* image, int stride, int y, int x0, int x1, int threshold, uint8_t* out,
                 FastBackend backend) {
#if defined(MCSLAM_ORB_HAVE_NATIVE)
  if (backend == FastBackend::kNative) return scoreRow<NativeU8x16>(image, stride, y, x0, x1, threshold, out);
#endif
  return scoreRow<ScalarU8x16>(image, stride, y, x0, x1, threshold, out);
}

}  // namespace mcslam::orb_detail
