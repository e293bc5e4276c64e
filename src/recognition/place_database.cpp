#include "mcslam/recognition/place_database.hpp"

#include <algorithm>

namespace mcslam {

PlaceDatabase::PlaceDatabase(int word_count, int max_places, int max_words_per_place)
    : max_words_per_place_(max_words_per_place),
      head_(static_cast<std::size_t>(word_count), -1),
      // Every word's chain has at most one block that is not full.
      blocks_(static_cast<std::size_t>(max_places) * static_cast<std::size_t>(max_words_per_place) / kBlockPostings +
              static_cast<std::size_t>(std::min<int64_t>(word_count, int64_t{max_places} * max_words_per_place)) + 1),
      free_blocks_(blocks_.size()),
      entries_of_(static_cast<std::size_t>(max_places) * static_cast<std::size_t>(max_words_per_place)),
      word_count_of_(static_cast<std::size_t>(max_places), -1),
      selected_(static_cast<std::size_t>(max_words_per_place)),
      score_(static_cast<std::size_t>(max_places), 0.0f),
      touched_(static_cast<std::size_t>(max_places), 0) {
  clear();
}

std::span<const BowEntry> PlaceDatabase::heaviest(const BowVector& v) {
  const std::span<const BowEntry> all = v.entries();
  const std::size_t keep = std::min(all.size(), selected_.size());
  std::copy(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(std::min(all.size(), selected_.size())),
            selected_.begin());
  if (all.size() > selected_.size()) {
    // Keep the heaviest: replace the lightest kept entry by each heavier one that follows, then restore word order.
    auto lighter = [](const BowEntry& a, const BowEntry& b) { return a.weight > b.weight; };
    std::make_heap(selected_.begin(), selected_.end(), lighter);
    for (std::size_t i = selected_.size(); i < all.size(); ++i) {
      if (all[i].weight <= selected_.front().weight) continue;
      std::pop_heap(selected_.begin(), selected_.end(), lighter);
      selected_.back() = all[i];
      std::push_heap(selected_.begin(), selected_.end(), lighter);
    }
    std::sort(selected_.begin(), selected_.end(), [](const BowEntry& a, const BowEntry& b) { return a.word < b.word; });
  }
  return {selected_.data(), keep};
}

void PlaceDatabase::addPosting(WordId w, Posting p) {
  int32_t& head = head_[static_cast<std::size_t>(w)];
  if (head < 0 || blocks_[static_cast<std::size_t>(head)].count == kBlockPostings) {
    const int32_t b = free_blocks_[static_cast<std::size_t>(--free_block_count_)];
    blocks_[static_cast<std::size_t>(b)].next = head;
    blocks_[static_cast<std::size_t>(b)].count = 0;
    head = b;
  }
  Block& block = blocks_[static_cast<std::size_t>(head)];
  block.postings[block.count++] = p;
}

// The place's posting takes the word's newest one (the last of its head block); an emptied head block returns to
// the pool.
void PlaceDatabase::removePosting(WordId w, int32_t place) {
  int32_t& head = head_[static_cast<std::size_t>(w)];
  Block& first = blocks_[static_cast<std::size_t>(head)];
  for (int32_t b = head; b >= 0; b = blocks_[static_cast<std::size_t>(b)].next) {
    Block& block = blocks_[static_cast<std::size_t>(b)];
    for (int i = 0; i < block.count; ++i) {
      if (block.postings[i].place != place) continue;
      block.postings[i] = first.postings[--first.count];
      if (first.count == 0) {
        free_blocks_[static_cast<std::size_t>(free_block_count_++)] = head;
        head = first.next;
      }
      return;
    }
  }
}

void PlaceDatabase::insert(int place, const BowVector& v) {
  if (contains(place)) erase(place);
  const std::span<const BowEntry> entries = heaviest(v);
  const std::size_t base = static_cast<std::size_t>(place) * static_cast<std::size_t>(max_words_per_place_);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    addPosting(entries[i].word, {place, entries[i].weight});
    entries_of_[base + i] = entries[i];
  }
  word_count_of_[static_cast<std::size_t>(place)] = static_cast<int32_t>(entries.size());
  ++stored_;
}

void PlaceDatabase::erase(int place) {
  const int32_t count = word_count_of_[static_cast<std::size_t>(place)];
  if (count < 0) return;
  const std::size_t base = static_cast<std::size_t>(place) * static_cast<std::size_t>(max_words_per_place_);
  for (int32_t i = 0; i < count; ++i) removePosting(entries_of_[base + static_cast<std::size_t>(i)].word, place);
  word_count_of_[static_cast<std::size_t>(place)] = -1;
  --stored_;
}

std::span<const BowEntry> PlaceDatabase::entries(int place) const {
  const int32_t count = word_count_of_[static_cast<std::size_t>(place)];
  if (count < 0) return {};
  return {entries_of_.data() + static_cast<std::size_t>(place) * static_cast<std::size_t>(max_words_per_place_),
          static_cast<std::size_t>(count)};
}

void PlaceDatabase::clear() {
  std::fill(head_.begin(), head_.end(), -1);
  std::fill(word_count_of_.begin(), word_count_of_.end(), -1);
  free_block_count_ = static_cast<int>(blocks_.size());
  for (int i = 0; i < free_block_count_; ++i) free_blocks_[static_cast<std::size_t>(i)] = free_block_count_ - 1 - i;
  stored_ = 0;
}

void PlaceDatabase::accumulate(const BowVector& v) const {
  touched_count_ = 0;
  for (const BowEntry& e : v.entries()) {
    for (int32_t b = head_[static_cast<std::size_t>(e.word)]; b >= 0; b = blocks_[static_cast<std::size_t>(b)].next) {
      const Block& block = blocks_[static_cast<std::size_t>(b)];
      for (int i = 0; i < block.count; ++i) {
        const Posting& posting = block.postings[i];
        float& score = score_[static_cast<std::size_t>(posting.place)];
        if (score == 0) touched_[static_cast<std::size_t>(touched_count_++)] = posting.place;
        // A shared word adds the smaller weight; the smallest positive float keeps a touched place marked.
        score += std::max(std::min(e.weight, posting.weight), 1e-30f);
      }
    }
  }
}

int PlaceDatabase::keepBest(std::span<PlaceScore> out, int n, PlaceScore s) {
  const int capacity = static_cast<int>(out.size());
  if (capacity == 0) return 0;
  if (n == capacity && s.score <= out[static_cast<std::size_t>(n - 1)].score) return n;
  int i = std::min(n, capacity - 1);
  while (i > 0 && out[static_cast<std::size_t>(i - 1)].score < s.score) {
    out[static_cast<std::size_t>(i)] = out[static_cast<std::size_t>(i - 1)];
    --i;
  }
  out[static_cast<std::size_t>(i)] = s;
  return std::min(n + 1, capacity);
}

}  // namespace mcslam
