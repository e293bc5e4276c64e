#pragma once
// The FAST-9 score kernel over a vector type V (ScalarU8x16, NativeU8x16, the AVX2 U8x32 of
// orb_avx2.cpp), in an anonymous namespace so that each kernel's translation unit has its own copy:
// the AVX2 unit is compiled with -mavx2, and nothing it instantiates may be shared with (and picked by the
// linker for) the baseline code. Hence also no standard-library templates in here.
#include <cstddef>
#include <cstdint>

namespace mcslam::orb_detail {
namespace {

// The 16-pixel Bresenham circle of radius 3, clockwise from the top.
constexpr int kCircleX[16] = {0, 1, 2, 3, 3, 3, 2, 1, 0, -1, -2, -3, -3, -3, -2, -1};
constexpr int kCircleY[16] = {-3, -3, -2, -1, 0, 1, 2, 3, 3, 3, 2, 1, 0, -1, -2, -3};

// max over the 16 arcs of 9 contiguous pixels of the smallest value on the arc.
template <class V>
[[gnu::always_inline]] inline V bestArcMinimum(const V (&d)[16]) {
  V m2[16], m4[16];
  for (int k = 0; k < 16; ++k) m2[k] = min(d[k], d[(k + 1) & 15]);
  for (int k = 0; k < 16; ++k) m4[k] = min(m2[k], m2[(k + 2) & 15]);
  V best = min(min(m4[0], m4[4]), d[8]);
  for (int k = 1; k < 16; ++k) best = max(best, min(min(m4[k], m4[(k + 4) & 15]), d[(k + 8) & 15]));
  return best;
}

// Stores the first n (<= V::kLanes) lanes: a partial group must not overwrite scores past the segment.
template <class V>
inline void storeScores(const V& v, uint8_t* out, int n) {
  if (n == V::kLanes) {
    v.store(out);
  } else {
    uint8_t lanes[V::kLanes];
    v.store(lanes);
    for (int i = 0; i < n; ++i) out[i] = lanes[i];
  }
}

template <class V>
int scoreRow(const uint8_t* image, int stride, int y, int x0, int x1, int threshold, uint8_t* out) {
  std::ptrdiff_t offsets[16];
  for (int k = 0; k < 16; ++k) offsets[k] = static_cast<std::ptrdiff_t>(kCircleY[k]) * stride + kCircleX[k];
  const V t = V::splat(static_cast<uint8_t>(threshold < 1 ? 1 : (threshold > 254 ? 254 : threshold)));
  const uint8_t* row = image + static_cast<std::ptrdiff_t>(y) * stride;
  int corners = 0;
  for (int x = x0; x < x1; x += V::kLanes) {
    const uint8_t* p = row + x;
    const V c = V::load(p);
    const V bright_limit = adds(c, t);
    const V dark_limit = subs(c, t);
    // Any 9-arc covers 4 consecutive of the 8 even circle pixels, among them two neighbouring compass
    // points (0, 4, 8, 12): two cheap necessary tests before the full score.
    V even[8];
    for (int k = 0; k < 8; k += 2) even[k] = V::load(p + offsets[2 * k]);
    const int n_out = x1 - x < V::kLanes ? x1 - x : V::kLanes;
    uint8_t* out_x = out + (x - x0);
    const auto compassBright = [&](int k) { return subs(even[k], bright_limit); };
    const auto compassDark = [&](int k) { return subs(dark_limit, even[k]); };
    const V bright_pair = max(max(min(compassBright(0), compassBright(2)), min(compassBright(2), compassBright(4))),
                              max(min(compassBright(4), compassBright(6)), min(compassBright(6), compassBright(0))));
    const V dark_pair = max(max(min(compassDark(0), compassDark(2)), min(compassDark(2), compassDark(4))),
                            max(min(compassDark(4), compassDark(6)), min(compassDark(6), compassDark(0))));
    if (!max(bright_pair, dark_pair).anyNonZero()) {
      storeScores(V::splat(0), out_x, n_out);
      continue;
    }
    for (int k = 1; k < 8; k += 2) even[k] = V::load(p + offsets[2 * k]);
    V run_bright[8], run_dark[8];  // pairs, then runs of 4 consecutive even pixels past the threshold
    for (int k = 0; k < 8; ++k) {
      run_bright[k] = min(subs(even[k], bright_limit), subs(even[(k + 1) & 7], bright_limit));
      run_dark[k] = min(subs(dark_limit, even[k]), subs(dark_limit, even[(k + 1) & 7]));
    }
    V bright4 = min(run_bright[0], run_bright[2]), dark4 = min(run_dark[0], run_dark[2]);
    for (int k = 1; k < 8; ++k) {
      bright4 = max(bright4, min(run_bright[k], run_bright[(k + 2) & 7]));
      dark4 = max(dark4, min(run_dark[k], run_dark[(k + 2) & 7]));
    }
    const bool maybe_bright = bright4.anyNonZero(), maybe_dark = dark4.anyNonZero();
    if (!maybe_bright && !maybe_dark) {
      storeScores(V::splat(0), out_x, n_out);
      continue;
    }
    // Full score, for the directions still possible.
    V pixels[16];
    for (int k = 0; k < 16; ++k) pixels[k] = (k & 1) ? V::load(p + offsets[k]) : even[k / 2];
    V score = V::splat(0);
    if (maybe_bright) {
      V d[16];
      for (int k = 0; k < 16; ++k) d[k] = subs(pixels[k], c);
      score = bestArcMinimum(d);
    }
    if (maybe_dark) {
      V d[16];
      for (int k = 0; k < 16; ++k) d[k] = subs(c, pixels[k]);
      score = max(score, bestArcMinimum(d));
    }
    score = keepAbove(score, t);
    if (score.anyNonZero()) {
      uint8_t scores[V::kLanes];
      score.store(scores);
      for (int i = 0; i < n_out; ++i) corners += scores[i] != 0;
    }
    storeScores(score, out_x, n_out);
  }
  return corners;
}

}  // namespace
}  // namespace mcslam::orb_detail
