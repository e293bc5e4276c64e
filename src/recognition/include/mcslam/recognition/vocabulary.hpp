#pragma once
// A vocabulary of binary visual words: a tree of ORB descriptors with `branching` children per node and `depth`
// levels below the root (hierarchical k-majority clustering, as DBoW2 builds it). A descriptor's word is the leaf
// reached by descending to the nearest child (Hamming distance) at every level; each word has an inverse document
// frequency (idf) from the training images. Read-only after construction, so any number of threads may transform
// descriptors at once; transforming allocates nothing.
//
// The tree is stored complete and implicit: node n's children are nodes branching*n+1 ... branching*n+branching,
// level l starts at node (branching^l - 1) / (branching - 1). A cluster that training left empty is an absent node;
// every present node above the leaves has at least one present child, so a descent always ends on a present leaf.
#include <cstdint>
#include <string>
#include <vector>

#include "mcslam/features/keypoint.hpp"

namespace mcslam {

using WordId = int32_t;  // index of a leaf within the leaf level, [0, wordCount())

class Vocabulary {
 public:
  static constexpr int kMaxBranching = 64;
  static constexpr int kMaxDepth = 8;
  static constexpr int64_t kMaxWords = int64_t{1} << 24;

  Vocabulary() = default;
  // An empty tree (every node absent) of this shape. Throws InputError for a shape outside the limits above.
  Vocabulary(int branching, int depth);

  int branching() const { return branching_; }
  int depth() const { return depth_; }
  int wordCount() const { return static_cast<int>(idf_.size()); }
  int64_t nodeCount() const { return static_cast<int64_t>(present_.size()); }
  bool empty() const { return present_.empty() || !present_[0]; }

  // The word of a descriptor.
  WordId word(const Descriptor& d) const;
  // The node `levels_up` levels above word w, as an index within its level: words sharing it are close in the
  // tree (for matching features word by word's neighbourhood, as DBoW2's direct index).
  int32_t ancestor(WordId w, int levels_up) const;
  float idf(WordId w) const { return idf_[static_cast<std::size_t>(w)]; }

  // The tree, for the trainer and the file.
  int64_t firstNodeOfLevel(int level) const;
  bool present(int64_t node) const { return present_[static_cast<std::size_t>(node)] != 0; }
  const Descriptor& descriptor(int64_t node) const { return nodes_[static_cast<std::size_t>(node)]; }
  void setNode(int64_t node, const Descriptor& d);
  void setIdf(WordId w, float idf) { idf_[static_cast<std::size_t>(w)] = idf; }

  // What it was trained on (kept in the file, shown by the tools).
  uint64_t training_images = 0;
  uint64_t training_descriptors = 0;

 private:
  int branching_ = 0;
  int depth_ = 0;
  std::vector<Descriptor> nodes_;
  std::vector<uint8_t> present_;
  std::vector<float> idf_;  // per word
};

// The vocabulary file: versioned binary with a checksum. Throws InputError naming the file and what is wrong with
// it (missing, not a vocabulary, another version, a shape outside the limits, truncated, corrupt).
Vocabulary readVocabularyFile(const std::string& path);
// Where the shipped vocabulary is looked for, in order: beside the executable (../share/mcslam/places/), the
// source tree's config/places/, the install folder.
std::vector<std::string> defaultVocabularyCandidates();
// `path`, or with an empty path the first default candidate that exists. Throws InputError (naming every path
// tried when none exists).
Vocabulary loadVocabulary(const std::string& path);
// Written whole or not at all (writeFileSynced). Throws InputError naming the file when it cannot.
void writeVocabularyFile(const Vocabulary& vocabulary, const std::string& path);

// CRC-32 of the words (nodes and idf): a map file keeps it, so that it is only used with the vocabulary it was made
// with.
uint32_t vocabularyFingerprint(const Vocabulary& vocabulary);

}  // namespace mcslam
