#pragma once
// Keypoints and 256-bit binary descriptors (ORB/rBRIEF), stored in fixed-capacity arrays.
#include <array>
#include <bit>
#include <cstdint>
#include <vector>

namespace mcslam {

struct Keypoint {
  float x = 0, y = 0;  // level-0 pixel coordinates (centre of pixel (0,0) at (0,0))
  float angle = 0;     // orientation, radians, from the intensity centroid
  float response = 0;  // corner score (higher is stronger)
  int8_t octave = 0;   // pyramid level it was detected at
};

using Descriptor = std::array<uint64_t, 4>;  // 256 bits

inline int hammingDistance(const Descriptor& a, const Descriptor& b) {
  return std::popcount(a[0] ^ b[0]) + std::popcount(a[1] ^ b[1]) + std::popcount(a[2] ^ b[2]) +
         std::popcount(a[3] ^ b[3]);
}

// Lowe's ratio test on Hamming distances: the best match is distinctly better than the second best.
inline bool passesRatioTest(int best, int second, float ratio) {
  return static_cast<float>(best) < ratio * static_cast<float>(second);
}

// The features of one image. Capacity is fixed at construction; `count` says how many are valid.
struct FeatureSet {
  std::vector<Keypoint> keypoints;
  std::vector<Descriptor> descriptors;
  int count = 0;

  FeatureSet() = default;
  explicit FeatureSet(int capacity) { reserve(capacity); }
  void reserve(int capacity) {
    keypoints.resize(capacity);
    descriptors.resize(capacity);
  }
  int capacity() const { return static_cast<int>(keypoints.size()); }
  void clear() { count = 0; }
};

}  // namespace mcslam
