#pragma once
// Building blocks of our RANSAC loops: a seeded random generator that gives the same sequence on
// every platform and standard library (std::uniform_int_distribution does not), and the adaptive
// number of iterations.
#include <algorithm>
#include <cmath>
#include <cstdint>

namespace mcslam {

// SplitMix64: tiny state, good statistical quality, trivially seeded.
class RansacRandom {
 public:
  explicit RansacRandom(uint64_t seed = 1) : state_(seed) {}
  void seed(uint64_t s) { state_ = s; }

  uint64_t next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }

  // Uniform in [0, n), n > 0 (Lemire's multiply-shift; the bias is below 2^-32 for our n).
  int below(int n) {
    return static_cast<int>((static_cast<unsigned __int128>(next() >> 32) * static_cast<uint64_t>(n)) >> 32);
  }

  // k distinct indices from [0, n) into out (k small; rejection of repeats). Requires n >= k.
  void distinct(int n, int k, int* out) {
    for (int i = 0; i < k; ++i) {
      int v;
      bool repeat;
      do {
        v = below(n);
        repeat = std::find(out, out + i, v) != out + i;
      } while (repeat);
      out[i] = v;
    }
  }

 private:
  uint64_t state_;
};

// Samples needed to draw, with probability `confidence`, at least one all-inlier sample of
// `sample_size` when a fraction `inlier_ratio` of the data are inliers.
inline int ransacIterationsNeeded(double inlier_ratio, int sample_size, double confidence) {
  const double all_inliers = std::pow(std::clamp(inlier_ratio, 0.0, 1.0), sample_size);
  if (all_inliers >= 1.0) return 1;
  if (all_inliers <= 0.0) return INT32_MAX;
  const double n = std::log(1.0 - confidence) / std::log1p(-all_inliers);
  return n >= static_cast<double>(INT32_MAX) ? INT32_MAX : static_cast<int>(std::ceil(n));
}

}  // namespace mcslam
