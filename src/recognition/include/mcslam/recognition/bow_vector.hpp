#pragma once
// Bag-of-words vectors of a place: tf-idf weights of the words its features fall in, sorted by word and
// L1-normalized, so that the similarity of two places is the sum over their shared words of the smaller weight
// (1 - |a - b|_1 / 2, DBoW2's L1 score): 1 for the same distribution of words, 0 for no word in common.
// A rig's place is all its cameras together: the words of every camera's features go into one vector, so a place
// seen before by one camera is recognized when another one sees it now.
#include <cstdint>
#include <span>
#include <vector>

#include "mcslam/features/frame_features.hpp"
#include "mcslam/recognition/vocabulary.hpp"

namespace mcslam {

struct BowEntry {
  WordId word = 0;
  float weight = 0;
};

// A fixed-capacity sparse vector.
class BowVector {
 public:
  BowVector() = default;
  explicit BowVector(int capacity) : entries_(static_cast<std::size_t>(capacity)) {}

  std::span<const BowEntry> entries() const { return {entries_.data(), static_cast<std::size_t>(size_)}; }
  int size() const { return size_; }
  int capacity() const { return static_cast<int>(entries_.size()); }
  void clear() { size_ = 0; }
  // Appends an entry (words must come in increasing order); false when full.
  bool push(WordId word, float weight);
  // Scales the weights to sum to one (nothing for an empty vector).
  void normalize();

 private:
  std::vector<BowEntry> entries_;
  int size_ = 0;
};

// Similarity of two normalized vectors, in [0, 1].
float bowSimilarity(const BowVector& a, const BowVector& b);

// The words of one rig frame's features and its BoW vector, in buffers sized at construction.
class FrameWords {
 public:
  FrameWords() = default;
  // `direct_levels_up`: how far above the leaves the node that groups features for matching lies (node()).
  FrameWords(int cameras, int max_features_per_camera, int direct_levels_up = 2);

  // Words of every present camera's keypoints, and the vector of them all. Allocation-free.
  void compute(const Vocabulary& vocabulary, const FrameFeatures& frame);

  const BowVector& bow() const { return bow_; }
  WordId word(int cam, int kp) const { return words_[static_cast<std::size_t>(cam)][static_cast<std::size_t>(kp)]; }
  // The tree node `direct_levels_up` above the keypoint's word: keypoints of two places are compared only within
  // the same node, which keeps matching fast without losing the near misses of a word boundary.
  int32_t node(int cam, int kp) const { return nodes_[static_cast<std::size_t>(cam)][static_cast<std::size_t>(kp)]; }
  int directLevelsUp() const { return direct_levels_up_; }

 private:
  std::vector<std::vector<WordId>> words_;
  std::vector<std::vector<int32_t>> nodes_;
  std::vector<WordId> sorted_;  // scratch: every word of the frame, sorted to count them
  BowVector bow_;
  int direct_levels_up_ = 2;
};

}  // namespace mcslam
