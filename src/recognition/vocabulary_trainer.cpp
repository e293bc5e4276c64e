#include "mcslam/recognition/vocabulary_trainer.hpp"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <random>
#include <vector>

#include "mcslam/core/error.hpp"
#include "mcslam/core/worker_pool.hpp"

namespace mcslam {

namespace {

// A node to split: its descriptors are indices [begin, end) of the shared index array.
struct NodeRange {
  int64_t node = 0;
  std::size_t begin = 0, end = 0;
};

Descriptor bitwiseMajority(std::span<const Descriptor> all, std::span<const uint32_t> members) {
  std::array<uint32_t, 256> ones{};
  for (uint32_t m : members) {
    const Descriptor& d = all[m];
    for (int word = 0; word < 4; ++word) {
      uint64_t bits = d[static_cast<std::size_t>(word)];
      while (bits) {
        ones[static_cast<std::size_t>(word * 64 + std::countr_zero(bits))]++;
        bits &= bits - 1;
      }
    }
  }
  Descriptor centre{};
  const std::size_t half = members.size() / 2;
  for (std::size_t bit = 0; bit < 256; ++bit)
    if (ones[bit] > half) centre[bit / 64] |= uint64_t{1} << (bit % 64);
  return centre;
}

// k-means++: the first centre at random, each next one with probability proportional to the squared distance
// to the nearest centre so far.
std::vector<Descriptor> seedCentres(std::span<const Descriptor> all, std::span<const uint32_t> members, int k,
                                    std::mt19937_64& rng) {
  std::vector<Descriptor> centres;
  std::vector<double> nearest(members.size(), static_cast<double>(INT_MAX));
  centres.push_back(all[members[std::uniform_int_distribution<std::size_t>(0, members.size() - 1)(rng)]]);
  while (static_cast<int>(centres.size()) < k) {
    double total = 0;
    for (std::size_t i = 0; i < members.size(); ++i) {
      const double d = hammingDistance(all[members[i]], centres.back());
      nearest[i] = std::min(nearest[i], d * d);
      total += nearest[i];
    }
    if (total <= 0) break;  // every member equals a centre already
    double pick = std::uniform_real_distribution<double>(0, total)(rng);
    std::size_t chosen = members.size() - 1;
    for (std::size_t i = 0; i < members.size(); ++i) {
      pick -= nearest[i];
      if (pick <= 0) {
        chosen = i;
        break;
      }
    }
    centres.push_back(all[members[chosen]]);
  }
  return centres;
}

class Trainer {
 public:
  Trainer(std::span<const Descriptor> all, const VocabularyTrainingOptions& options)
      : all_(all), options_(options), vocabulary_(options.branching, options.depth), index_(all.size()) {
    for (std::size_t i = 0; i < index_.size(); ++i) index_[i] = static_cast<uint32_t>(i);
  }

  Vocabulary build() {
    std::vector<NodeRange> level{{0, 0, index_.size()}};
    WorkerPool pool(options_.threads > 0 ? options_.threads - 1 : WorkerPool::hardwareThreads() - 1);
    for (int depth = 0; depth < options_.depth; ++depth) {
      std::vector<std::vector<NodeRange>> children(level.size());
      pool.forEach(static_cast<int>(level.size()),
                   [&](int i) { children[static_cast<std::size_t>(i)] = split(level[static_cast<std::size_t>(i)]); });
      level.clear();
      for (const auto& c : children) level.insert(level.end(), c.begin(), c.end());
    }
    return std::move(vocabulary_);
  }

 private:
  // Clusters one node's descriptors into its children (setting their centres) and returns their ranges.
  std::vector<NodeRange> split(const NodeRange& range) {
    const int k = options_.branching;
    const std::span<uint32_t> members(index_.data() + range.begin, range.end - range.begin);
    const int64_t first_child = range.node * k + 1;
    std::vector<NodeRange> out;
    if (static_cast<int>(members.size()) <= k) {  // each descriptor its own child
      for (std::size_t i = 0; i < members.size(); ++i) {
        vocabulary_.setNode(first_child + static_cast<int64_t>(i), all_[members[i]]);
        out.push_back({first_child + static_cast<int64_t>(i), range.begin + i, range.begin + i + 1});
      }
      return out;
    }
    std::mt19937_64 rng(options_.seed ^ (static_cast<uint64_t>(range.node) * 0x9E3779B97F4A7C15ull));
    std::vector<Descriptor> centres = seedCentres(all_, members, k, rng);
    std::vector<int> cluster(members.size(), -1);
    for (int iteration = 0; iteration < options_.iterations; ++iteration) {
      if (!assign(members, centres, cluster) && iteration > 0) break;
      updateCentres(members, cluster, centres);
    }
    assign(members, centres, cluster);
    return partition(range, members, centres, cluster);
  }

  // Nearest centre of each member; true when any member changed cluster.
  bool assign(std::span<const uint32_t> members, const std::vector<Descriptor>& centres, std::vector<int>& cluster) {
    bool changed = false;
    for (std::size_t i = 0; i < members.size(); ++i) {
      int best = 0, best_distance = INT_MAX;
      for (std::size_t c = 0; c < centres.size(); ++c) {
        const int d = hammingDistance(all_[members[i]], centres[c]);
        if (d < best_distance) {
          best_distance = d;
          best = static_cast<int>(c);
        }
      }
      changed |= cluster[i] != best;
      cluster[i] = best;
    }
    return changed;
  }

  void updateCentres(std::span<const uint32_t> members, const std::vector<int>& cluster,
                     std::vector<Descriptor>& centres) {
    std::vector<std::vector<uint32_t>> of(centres.size());
    for (std::size_t i = 0; i < members.size(); ++i) of[static_cast<std::size_t>(cluster[i])].push_back(members[i]);
    for (std::size_t c = 0; c < centres.size(); ++c)
      if (!of[c].empty()) centres[c] = bitwiseMajority(all_, of[c]);
  }

  // Reorders the node's index range cluster by cluster; the non-empty clusters become present children.
  std::vector<NodeRange> partition(const NodeRange& range, std::span<uint32_t> members,
                                   const std::vector<Descriptor>& centres, const std::vector<int>& cluster) {
    const int64_t first_child = range.node * options_.branching + 1;
    std::vector<std::vector<uint32_t>> of(centres.size());
    for (std::size_t i = 0; i < members.size(); ++i) of[static_cast<std::size_t>(cluster[i])].push_back(members[i]);
    std::vector<NodeRange> out;
    std::size_t at = range.begin;
    for (std::size_t c = 0; c < centres.size(); ++c) {
      if (of[c].empty()) continue;
      std::copy(of[c].begin(), of[c].end(), index_.begin() + static_cast<std::ptrdiff_t>(at));
      vocabulary_.setNode(first_child + static_cast<int64_t>(c), centres[c]);
      out.push_back({first_child + static_cast<int64_t>(c), at, at + of[c].size()});
      at += of[c].size();
    }
    return out;
  }

  std::span<const Descriptor> all_;
  VocabularyTrainingOptions options_;
  Vocabulary vocabulary_;
  std::vector<uint32_t> index_;
};

// idf(w) = log(images / images containing w); a word no training image reaches gets the rarest weight.
void setIdf(Vocabulary& v, std::span<const Descriptor> all, std::span<const uint64_t> image_offsets) {
  const std::size_t images = image_offsets.size() - 1;
  std::vector<uint32_t> containing(static_cast<std::size_t>(v.wordCount()), 0);
  std::vector<int64_t> last_image(static_cast<std::size_t>(v.wordCount()), -1);
  for (std::size_t i = 0; i < images; ++i) {
    for (uint64_t d = image_offsets[i]; d < image_offsets[i + 1]; ++d) {
      const auto w = static_cast<std::size_t>(v.word(all[d]));
      if (last_image[w] == static_cast<int64_t>(i)) continue;
      last_image[w] = static_cast<int64_t>(i);
      ++containing[w];
    }
  }
  for (WordId w = 0; w < v.wordCount(); ++w) {
    const uint32_t n = containing[static_cast<std::size_t>(w)];
    v.setIdf(w, static_cast<float>(std::log(static_cast<double>(images) / std::max<uint32_t>(n, 1))));
  }
}

}  // namespace

Vocabulary trainVocabulary(std::span<const Descriptor> descriptors, std::span<const uint64_t> image_offsets,
                           const VocabularyTrainingOptions& options) {
  if (image_offsets.size() < 2 || image_offsets.back() != descriptors.size())
    throw InputError("vocabulary training: image offsets do not cover the descriptors");
  if (descriptors.size() < static_cast<std::size_t>(options.branching))
    throw InputError("vocabulary training: " + std::to_string(descriptors.size()) + " descriptors, fewer than the " +
                     std::to_string(options.branching) + " of one node's children");
  if (descriptors.size() > UINT32_MAX) throw InputError("vocabulary training: more than 2^32 descriptors");
  Vocabulary v = Trainer(descriptors, options).build();
  v.setNode(0, Descriptor{});
  setIdf(v, descriptors, image_offsets);
  v.training_images = image_offsets.size() - 1;
  v.training_descriptors = descriptors.size();
  return v;
}

}  // namespace mcslam
