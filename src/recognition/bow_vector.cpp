#include "mcslam/recognition/bow_vector.hpp"

#include <algorithm>
#include <cassert>

namespace mcslam {

bool BowVector::push(WordId word, float weight) {
  if (size_ == capacity()) return false;
  assert(size_ == 0 || entries_[static_cast<std::size_t>(size_ - 1)].word < word);
  entries_[static_cast<std::size_t>(size_++)] = {word, weight};
  return true;
}

void BowVector::normalize() {
  double sum = 0;
  for (const BowEntry& e : entries()) sum += e.weight;
  if (sum <= 0) return;
  const auto scale = static_cast<float>(1.0 / sum);
  for (int i = 0; i < size_; ++i) entries_[static_cast<std::size_t>(i)].weight *= scale;
}

float bowSimilarity(const BowVector& a, const BowVector& b) {
  const std::span<const BowEntry> x = a.entries();
  const std::span<const BowEntry> y = b.entries();
  std::size_t i = 0, j = 0;
  double score = 0;
  while (i < x.size() && j < y.size()) {
    if (x[i].word < y[j].word) {
      ++i;
    } else if (y[j].word < x[i].word) {
      ++j;
    } else {
      score += std::min(x[i].weight, y[j].weight);
      ++i;
      ++j;
    }
  }
  return static_cast<float>(score);
}

FrameWords::FrameWords(int cameras, int max_features_per_camera, int direct_levels_up)
    : words_(static_cast<std::size_t>(cameras), std::vector<WordId>(static_cast<std::size_t>(max_features_per_camera))),
      nodes_(static_cast<std::size_t>(cameras),
             std::vector<int32_t>(static_cast<std::size_t>(max_features_per_camera))),
      sorted_(static_cast<std::size_t>(cameras) * static_cast<std::size_t>(max_features_per_camera)),
      bow_(cameras * max_features_per_camera),
      direct_levels_up_(direct_levels_up) {}

void FrameWords::compute(const Vocabulary& vocabulary, const FrameFeatures& frame) {
  const int levels_up = std::min(direct_levels_up_, vocabulary.depth());
  std::size_t total = 0;
  for (int c = 0; c < frame.cameras() && c < static_cast<int>(words_.size()); ++c) {
    if (!frame.present[static_cast<std::size_t>(c)]) continue;
    const FeatureSet& set = frame.sets[static_cast<std::size_t>(c)];
    const int n = std::min(set.count, static_cast<int>(words_[static_cast<std::size_t>(c)].size()));
    for (int k = 0; k < n; ++k) {
      const WordId w = vocabulary.word(set.descriptors[static_cast<std::size_t>(k)]);
      words_[static_cast<std::size_t>(c)][static_cast<std::size_t>(k)] = w;
      nodes_[static_cast<std::size_t>(c)][static_cast<std::size_t>(k)] = vocabulary.ancestor(w, levels_up);
      sorted_[total++] = w;
    }
  }
  std::sort(sorted_.begin(), sorted_.begin() + static_cast<std::ptrdiff_t>(total));
  bow_.clear();
  // tf-idf: a word's share of the place's features times its rarity in the training images.
  for (std::size_t i = 0; i < total;) {
    std::size_t j = i;
    while (j < total && sorted_[j] == sorted_[i]) ++j;
    const float weight = static_cast<float>(j - i) * vocabulary.idf(sorted_[i]);
    if (weight > 0) bow_.push(sorted_[i], weight);
    i = j;
  }
  bow_.normalize();
}

}  // namespace mcslam
