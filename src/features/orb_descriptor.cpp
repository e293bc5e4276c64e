#include "orb_descriptor.hpp"

#include <cmath>
#include <cstddef>
#include <numbers>

namespace mcslam::orb_detail {
namespace {

constexpr float kTwoPi = 2.0f * std::numbers::pi_v<float>;

// splitmix64: a tiny, well-mixed generator whose output is the same on every platform (unlike
// std::normal_distribution), so the pattern and therefore the descriptors are too.
struct SplitMix64 {
  uint64_t state;
  uint64_t next() {
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  // Sum of 12 uniforms: unit variance, close to Gaussian, and only exact IEEE operations.
  double normal() {
    double s = -6.0;
    for (int i = 0; i < 12; ++i) s += uniform();
    return s;
  }
};

// The disc of the intensity centroid: points with u^2 + v^2 <= r^2 + r (symmetric under u <-> v).
struct Disc {
  int half_width[kPatchRadius + 1];
  Disc() {
    for (int v = 0; v <= kPatchRadius; ++v) {
      int u = 0;
      while ((u + 1) * (u + 1) + v * v <= kPatchRadius * kPatchRadius + kPatchRadius) ++u;
      half_width[v] = u;
    }
  }
};
const Disc kDisc;

void rotatePattern(RotatedPattern& rotated) {
  PatternPoint a[kTests], b[kTests];
  generateBriefPattern(a, b);
  for (int bin = 0; bin < kAngleBins; ++bin) {
    const double angle = 2.0 * std::numbers::pi * bin / kAngleBins;
    const double c = std::cos(angle), s = std::sin(angle);
    auto turn = [&](const PatternPoint& p, int8_t& x, int8_t& y) {
      x = static_cast<int8_t>(std::lround(c * p.x - s * p.y));
      y = static_cast<int8_t>(std::lround(s * p.x + c * p.y));
    };
    for (int i = 0; i < kTests; ++i) {
      PointPair& t = rotated.tests[bin][i];
      turn(a[i], t.ax, t.ay);
      turn(b[i], t.bx, t.by);
    }
  }
}

}  // namespace

void generateBriefPattern(PatternPoint (&a)[kTests], PatternPoint (&b)[kTests]) {
  // Both points i.i.d. from a wide Gaussian (sigma = 2 r) truncated to the disc of radius r, so that
  // any rotation stays within the patch: close to uniform over the disc, slightly denser at the centre.
  // BRIEF's sigma = patch / 5 packs the tests near the centre, where they are correlated, so its bits tell
  // rotated and rescaled views apart less well (docs/benchmarks/orb.md). Pairs closer than
  // 2 pixels compare nearly the same smoothed value and mostly encode noise: drawn again.
  constexpr double kSigma = 2.0 * kPatchRadius;
  constexpr double kMaxRadius2 = kPatchRadius * kPatchRadius;
  SplitMix64 rng{0x6d63736c616d4f52ull};
  auto draw = [&]() {
    while (true) {
      const double x = kSigma * rng.normal(), y = kSigma * rng.normal();
      if (x * x + y * y <= kMaxRadius2) return PatternPoint{static_cast<float>(x), static_cast<float>(y)};
    }
  };
  for (int i = 0; i < kTests; ++i) {
    while (true) {
      a[i] = draw();
      b[i] = draw();
      const float dx = a[i].x - b[i].x, dy = a[i].y - b[i].y;
      if (dx * dx + dy * dy >= 4.0f) break;
    }
  }
}

const RotatedPattern& rotatedPattern() {
  // Built on first use (thread-safe); OrbExtractor's constructor makes that first use.
  static const RotatedPattern& pattern = *[] {
    static RotatedPattern storage;
    rotatePattern(storage);
    return &storage;
  }();
  return pattern;
}

float intensityCentroidAngle(const uint8_t* center, int stride) {
  int m10 = 0, m01 = 0;
  for (int u = -kPatchRadius; u <= kPatchRadius; ++u) m10 += u * center[u];
  for (int v = 1; v <= kPatchRadius; ++v) {
    const uint8_t* below = center + static_cast<std::ptrdiff_t>(v) * stride;
    const uint8_t* above = center - static_cast<std::ptrdiff_t>(v) * stride;
    const int d = kDisc.half_width[v];
    int column_sum = 0;  // sum over the row pair of I(below) - I(above)
    for (int u = -d; u <= d; ++u) {
      column_sum += below[u] - above[u];
      m10 += u * (below[u] + above[u]);
    }
    m01 += v * column_sum;
  }
  float angle = std::atan2(static_cast<float>(m01), static_cast<float>(m10));
  if (angle < 0) angle += kTwoPi;
  return angle;
}

PatternOffsets::PatternOffsets(int stride) : stride_(stride), offsets_(static_cast<size_t>(kAngleBins) * 2 * kTests) {
  const RotatedPattern& pattern = rotatedPattern();
  for (int bin = 0; bin < kAngleBins; ++bin) {
    int32_t* out = offsets_.data() + static_cast<size_t>(bin) * 2 * kTests;
    for (int i = 0; i < kTests; ++i) {
      const PointPair& t = pattern.tests[bin][i];
      out[2 * i] = t.ay * stride + t.ax;
      out[2 * i + 1] = t.by * stride + t.bx;
    }
  }
}

const int32_t* PatternOffsets::forAngle(float angle) const {
  int bin = static_cast<int>(std::lround(angle * (kAngleBins / kTwoPi)));
  bin = ((bin % kAngleBins) + kAngleBins) % kAngleBins;
  return offsets_.data() + static_cast<size_t>(bin) * 2 * kTests;
}

void steeredBrief(const uint8_t* center, const int32_t* offsets, Descriptor& out) {
  for (int word = 0; word < 4; ++word) {
    uint64_t bits = 0;
    const int32_t* o = offsets + word * 128;
    for (int i = 0; i < 64; ++i) bits |= static_cast<uint64_t>(center[o[2 * i]] < center[o[2 * i + 1]]) << i;
    out[word] = bits;
  }
}

}  // namespace mcslam::orb_detail
