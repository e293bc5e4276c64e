#pragma once
// Synthetic descriptors for the recognition tests: clusters of descriptors around random centres, each member a
// few bits away from its centre, so that the right clustering is known.
#include <cstdint>
#include <random>
#include <vector>

#include "mcslam/features/keypoint.hpp"

namespace mcslam::test {

inline Descriptor randomDescriptor(std::mt19937_64& rng) { return {rng(), rng(), rng(), rng()}; }

inline Descriptor flipBits(Descriptor d, int bits, std::mt19937_64& rng) {
  std::uniform_int_distribution<int> bit(0, 255);
  for (int i = 0; i < bits; ++i) {
    const int b = bit(rng);
    d[static_cast<std::size_t>(b / 64)] ^= uint64_t{1} << (b % 64);
  }
  return d;
}

struct ClusteredDescriptors {
  std::vector<Descriptor> centres;
  std::vector<Descriptor> descriptors;
  std::vector<int> cluster_of;          // per descriptor
  std::vector<uint64_t> image_offsets;  // one "image" per cluster
};

// `clusters` centres, `per_cluster` members each within `noise_bits` flipped bits; image i holds cluster i.
inline ClusteredDescriptors clusteredDescriptors(int clusters, int per_cluster, int noise_bits, uint64_t seed) {
  std::mt19937_64 rng(seed);
  ClusteredDescriptors out;
  out.image_offsets.push_back(0);
  for (int c = 0; c < clusters; ++c) {
    out.centres.push_back(randomDescriptor(rng));
    for (int i = 0; i < per_cluster; ++i) {
      out.descriptors.push_back(flipBits(out.centres.back(), noise_bits, rng));
      out.cluster_of.push_back(c);
    }
    out.image_offsets.push_back(out.descriptors.size());
  }
  return out;
}

}  // namespace mcslam::test
