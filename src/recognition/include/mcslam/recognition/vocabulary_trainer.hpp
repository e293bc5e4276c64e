#pragma once
// Training a vocabulary offline (mcslam-places train-vocabulary): hierarchical k-majority clustering of ORB
// descriptors (k-means++ seeding, bitwise-majority centres), then the words' idf over the training images.
// Deterministic for a given seed, whatever the thread count. Allocates freely: this is not run on the robot.
#include <cstdint>
#include <span>

#include "mcslam/recognition/vocabulary.hpp"

namespace mcslam {

struct VocabularyTrainingOptions {
  int branching = 10;
  int depth = 5;
  int iterations = 10;  // k-majority iterations per node at most (it stops earlier once nothing moves)
  uint64_t seed = 1;
  int threads = 0;  // 0: all cores
};

// `descriptors` holds the training images' descriptors one image after the other; image i has descriptors
// [image_offsets[i], image_offsets[i + 1]) (so image_offsets has one entry more than there are images).
// Throws InputError when there are fewer descriptors than the vocabulary's branching.
Vocabulary trainVocabulary(std::span<const Descriptor> descriptors, std::span<const uint64_t> image_offsets,
                           const VocabularyTrainingOptions& options);

}  // namespace mcslam
