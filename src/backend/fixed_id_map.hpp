#pragma once
// Caller id -> pool slot, with a capacity fixed at construction (no allocation on insert).
// Open addressing with linear probing and backward-shift deletion (no tombstones).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace mcslam::backend {

class FixedIdMap {
 public:
  explicit FixedIdMap(int capacity) {
    size_t n = 16;
    while (n < size_t(capacity) * 2) n <<= 1;  // load factor <= 1/2
    keys_.assign(n, 0);
    values_.assign(n, kEmpty);
    mask_ = n - 1;
  }

  void clear() { std::fill(values_.begin(), values_.end(), kEmpty); }

  // -1 when absent.
  int find(int64_t key) const {
    for (size_t i = home(key);; i = (i + 1) & mask_) {
      if (values_[i] == kEmpty) return -1;
      if (keys_[i] == key) return values_[i];
    }
  }
  // The caller guarantees the key is absent and the map below capacity.
  void insert(int64_t key, int value) {
    size_t i = home(key);
    while (values_[i] != kEmpty) i = (i + 1) & mask_;
    keys_[i] = key;
    values_[i] = value;
  }
  void erase(int64_t key) {
    size_t i = home(key);
    while (true) {
      if (values_[i] == kEmpty) return;
      if (keys_[i] == key) break;
      i = (i + 1) & mask_;
    }
    // Shift back the following entries whose probe path crosses the hole.
    size_t hole = i;
    for (size_t j = (i + 1) & mask_; values_[j] != kEmpty; j = (j + 1) & mask_) {
      const size_t h = home(keys_[j]);
      const bool movable = hole <= j ? (h <= hole || h > j) : (h <= hole && h > j);
      if (movable) {
        keys_[hole] = keys_[j];
        values_[hole] = values_[j];
        hole = j;
      }
    }
    values_[hole] = kEmpty;
  }

 private:
  static constexpr int kEmpty = -1;
  size_t home(int64_t key) const {
    uint64_t x = static_cast<uint64_t>(key) * 0x9E3779B97F4A7C15ull;  // Fibonacci hashing
    return (x ^ (x >> 29)) & mask_;
  }
  std::vector<int64_t> keys_;
  std::vector<int> values_;
  size_t mask_ = 0;
};

}  // namespace mcslam::backend
