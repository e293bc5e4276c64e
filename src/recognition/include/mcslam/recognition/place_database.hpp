#pragma once
// The keyframe database of place recognition: an inverted index from each word to the stored places (keyframes)
// whose vector has it, with its weight. A query scores every place sharing a word with the query's vector
// (bowSimilarity, accumulated over the shared words' postings) and returns the best. All memory is allocated at
// construction from the capacities: `max_places` places of at most `max_words_per_place` words each (a place with
// more keeps its heaviest words). Inserting, erasing and querying allocate nothing.
//
// A word's postings are kept in blocks of kBlockPostings from one pool, chained from the word: a query reads a
// word's postings a cache line or two at a time, where a list of single postings would miss the cache on each.
//
// Places are identified by a slot in [0, max_places) that the caller owns (the place map's keyframe slot).
// Queries use scratch inside the database: one thread queries at a time, and not while another inserts or erases.
#include <cstdint>
#include <span>
#include <vector>

#include "mcslam/recognition/bow_vector.hpp"

namespace mcslam {

struct PlaceScore {
  int32_t place = -1;
  float score = 0;
};

class PlaceDatabase {
 public:
  PlaceDatabase() = default;
  PlaceDatabase(int word_count, int max_places, int max_words_per_place);

  int capacity() const { return static_cast<int>(word_count_of_.size()); }
  int maxWordsPerPlace() const { return max_words_per_place_; }
  int size() const { return stored_; }
  bool contains(int place) const { return word_count_of_[static_cast<std::size_t>(place)] >= 0; }

  // Stores `v` as place `place` (replacing what the slot held).
  void insert(int place, const BowVector& v);
  void erase(int place);
  void clear();
  // What place `place` keeps (its heaviest words, in word order; empty when the slot is): inserting it again
  // stores the same place.
  std::span<const BowEntry> entries(int place) const;

  // Writes into `out` the places with score >= min_score for which accept(place) is true, best first, at most
  // out.size() of them; returns how many.
  template <class Accept>
  int query(const BowVector& v, float min_score, std::span<PlaceScore> out, const Accept& accept) const {
    accumulate(v);
    int n = 0;
    for (int i = 0; i < touched_count_; ++i) {
      const int32_t place = touched_[static_cast<std::size_t>(i)];
      const float score = score_[static_cast<std::size_t>(place)];
      score_[static_cast<std::size_t>(place)] = 0;
      if (score < min_score || !accept(place)) continue;
      n = keepBest(out, n, {place, score});
    }
    return n;
  }
  int query(const BowVector& v, float min_score, std::span<PlaceScore> out) const {
    return query(v, min_score, out, [](int) { return true; });
  }

 private:
  static constexpr int kBlockPostings = 15;
  struct Posting {
    int32_t place = -1;
    float weight = 0;
  };
  // 128 bytes: the word's newest postings are in its head block, which alone may be partly filled.
  struct Block {
    int32_t next = -1;
    int32_t count = 0;
    Posting postings[kBlockPostings];
  };

  // Adds the query's overlap with every place sharing a word into score_, listing the places in touched_.
  void accumulate(const BowVector& v) const;
  // Inserts `s` into the sorted prefix out[0, n) if it is among the best out.size(); returns the new length.
  static int keepBest(std::span<PlaceScore> out, int n, PlaceScore s);
  // The `max_words_per_place_` heaviest entries of v, in word order, into selected_.
  std::span<const BowEntry> heaviest(const BowVector& v);

  void addPosting(WordId w, Posting p);
  void removePosting(WordId w, int32_t place);

  int max_words_per_place_ = 0;
  int stored_ = 0;
  std::vector<int32_t> head_;         // per word: its head block, -1 when none
  std::vector<Block> blocks_;         // the pool
  std::vector<int32_t> free_blocks_;  // a stack of unused block indices
  int free_block_count_ = 0;
  std::vector<BowEntry> entries_of_;    // place p's words: [p * max_words_per_place_, +word_count_of_[p])
  std::vector<int32_t> word_count_of_;  // per place: words stored, -1 when the slot is empty
  std::vector<BowEntry> selected_;      // scratch of insert()
  mutable std::vector<float> score_;
  mutable std::vector<int32_t> touched_;
  mutable int touched_count_ = 0;
};

}  // namespace mcslam
