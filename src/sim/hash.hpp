#pragma once
// Counter-based randomness: every random value is a pure function of (seed, indices), so rendering and
// world building give the same bytes whatever the thread count or evaluation order.
#include <cmath>
#include <cstdint>

namespace mcslam::sim {

inline uint64_t mix64(uint64_t x) {  // splitmix64 finaliser
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// 32-bit finaliser (Wellons' "lowbias32"): for the per-pixel sensor noise, which hashes every pixel of every
// frame and is cheaper with 32-bit products than with mix64's two 64-bit ones. U: uint32_t, or a vector of
// them (lanes hashed independently).
template <class U>
inline U hash32(U x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  return x ^ (x >> 16);
}

inline uint64_t hashOf(uint64_t a, uint64_t b) { return mix64(a ^ mix64(b)); }
inline uint64_t hashOf(uint64_t a, uint64_t b, uint64_t c) { return hashOf(hashOf(a, b), c); }
inline uint64_t hashOf(uint64_t a, uint64_t b, uint64_t c, uint64_t d) { return hashOf(hashOf(a, b, c), d); }

// Uniform in [0, 1) from the top 53 bits.
inline double unitFromHash(uint64_t h) { return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0); }

// A small sequential generator for building worlds and textures (seeded, portable, unlike std:: distributions).
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(mix64(seed)) {}
  uint64_t next() { return mix64(state_++); }
  double uniform() { return unitFromHash(next()); }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  int integer(int lo, int hi_inclusive) {
    return lo + static_cast<int>(uniform() * (hi_inclusive - lo + 1) * 0.9999999999);
  }
  bool chance(double p) { return uniform() < p; }
  double normal() {  // Box-Muller; one value per call keeps the stream simple
    const double u1 = 1.0 - uniform(), u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }

 private:
  uint64_t state_;
};

}  // namespace mcslam::sim
