#include "mcslam/recognition/vocabulary.hpp"

#include <climits>

#include "mcslam/core/error.hpp"

namespace mcslam {

namespace {

int64_t power(int base, int exponent) {
  int64_t p = 1;
  for (int i = 0; i < exponent; ++i) p *= base;
  return p;
}

}  // namespace

Vocabulary::Vocabulary(int branching, int depth) : branching_(branching), depth_(depth) {
  if (branching < 2 || branching > kMaxBranching)
    throw InputError("vocabulary branching " + std::to_string(branching) + " is outside [2, " +
                     std::to_string(kMaxBranching) + "]");
  if (depth < 1 || depth > kMaxDepth)
    throw InputError("vocabulary depth " + std::to_string(depth) + " is outside [1, " + std::to_string(kMaxDepth) +
                     "]");
  const int64_t words = power(branching, depth);
  if (words > kMaxWords)
    throw InputError("vocabulary of branching " + std::to_string(branching) + " and depth " + std::to_string(depth) +
                     " has " + std::to_string(words) + " words, more than " + std::to_string(kMaxWords));
  const int64_t nodes = (power(branching, depth + 1) - 1) / (branching - 1);
  nodes_.assign(static_cast<std::size_t>(nodes), Descriptor{});
  present_.assign(static_cast<std::size_t>(nodes), 0);
  idf_.assign(static_cast<std::size_t>(words), 0.0f);
}

int64_t Vocabulary::firstNodeOfLevel(int level) const { return (power(branching_, level) - 1) / (branching_ - 1); }

void Vocabulary::setNode(int64_t node, const Descriptor& d) {
  nodes_[static_cast<std::size_t>(node)] = d;
  present_[static_cast<std::size_t>(node)] = 1;
}

WordId Vocabulary::word(const Descriptor& d) const {
  int64_t node = 0;
  for (int level = 0; level < depth_; ++level) {
    const int64_t first_child = node * branching_ + 1;
    int64_t best = first_child;
    int best_distance = INT_MAX;
    for (int64_t c = first_child; c < first_child + branching_; ++c) {
      if (!present_[static_cast<std::size_t>(c)]) continue;
      const int distance = hammingDistance(d, nodes_[static_cast<std::size_t>(c)]);
      if (distance < best_distance) {
        best_distance = distance;
        best = c;
      }
    }
    node = best;
  }
  return static_cast<WordId>(node - firstNodeOfLevel(depth_));
}

int32_t Vocabulary::ancestor(WordId w, int levels_up) const {
  return static_cast<int32_t>(w / power(branching_, levels_up));
}

}  // namespace mcslam
