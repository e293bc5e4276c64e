#include "mcslam/recognition/place_database.hpp"

#include <algorithm>

namespace mcslam {

PlaceDatabase::PlaceDatabase(int word_count, int max_places, int max_words_per_place)
    : max_words_per_place_(max_words_per_place),
      head_(static_cast<std::size_t>(word_count), -1),
      postings_(static_cast<std::size_t>(max_places) * static_cast<std::size_t>(max_words_per_place)),
      word_count_of_(static_cast<std::size_t>(max_places), -1),
      word_of_posting_(postings_.size(), 0),
      selected_(static_cast<std::size_t>(max_words_per_place)),
      score_(static_cast<std::size_t>(max_places), 0.0f),
      touched_(static_cast<std::size_t>(max_places), 0) {}

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

void PlaceDatabase::insert(int place, const BowVector& v) {
  if (contains(place)) erase(place);
  const std::span<const BowEntry> entries = heaviest(v);
  const int32_t base = place * max_words_per_place_;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const int32_t p = base + static_cast<int32_t>(i);
    const WordId w = entries[i].word;
    Posting& posting = postings_[static_cast<std::size_t>(p)];
    posting = {place, entries[i].weight, -1, head_[static_cast<std::size_t>(w)]};
    if (posting.next >= 0) postings_[static_cast<std::size_t>(posting.next)].prev = p;
    head_[static_cast<std::size_t>(w)] = p;
    word_of_posting_[static_cast<std::size_t>(p)] = w;
  }
  word_count_of_[static_cast<std::size_t>(place)] = static_cast<int32_t>(entries.size());
  ++stored_;
}

void PlaceDatabase::erase(int place) {
  const int32_t count = word_count_of_[static_cast<std::size_t>(place)];
  if (count < 0) return;
  const int32_t base = place * max_words_per_place_;
  for (int32_t p = base; p < base + count; ++p) {
    const Posting& posting = postings_[static_cast<std::size_t>(p)];
    if (posting.prev >= 0) {
      postings_[static_cast<std::size_t>(posting.prev)].next = posting.next;
    } else {
      head_[static_cast<std::size_t>(word_of_posting_[static_cast<std::size_t>(p)])] = posting.next;
    }
    if (posting.next >= 0) postings_[static_cast<std::size_t>(posting.next)].prev = posting.prev;
  }
  word_count_of_[static_cast<std::size_t>(place)] = -1;
  --stored_;
}

void PlaceDatabase::clear() {
  std::fill(head_.begin(), head_.end(), -1);
  std::fill(word_count_of_.begin(), word_count_of_.end(), -1);
  stored_ = 0;
}

void PlaceDatabase::accumulate(const BowVector& v) const {
  touched_count_ = 0;
  for (const BowEntry& e : v.entries()) {
    for (int32_t p = head_[static_cast<std::size_t>(e.word)]; p >= 0;) {
      const Posting& posting = postings_[static_cast<std::size_t>(p)];
      float& score = score_[static_cast<std::size_t>(posting.place)];
      if (score == 0) touched_[static_cast<std::size_t>(touched_count_++)] = posting.place;
      // A shared word adds the smaller weight; the smallest positive float keeps a touched place marked.
      score += std::max(std::min(e.weight, posting.weight), 1e-30f);
      p = posting.next;
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
