#pragma once
// A lock-free single-producer/single-consumer queue of preallocated slots whose producer never blocks:
// when the queue is full, publishing a new item drops the oldest queued one (counted).
//
// Slots live in a fixed pool of capacity + 2 (capacity queued, one being written, one being read).
// Slot indices move between three places: the queue (a ring of indices whose head only the producer
// advances and whose tail both sides advance by compare-and-swap: the consumer to take, the producer
// to evict), the free list (consumer -> producer), and the two hands. A 64-bit monotonically growing
// tail cannot suffer ABA. Nothing is allocated after construction.
#include <atomic>
#include <cstdint>
#include <memory>
#include <new>
#include <stdexcept>

namespace mcslam::platform {

// Plain SPSC ring of small integers; used as the free list.
class IndexRing {
 public:
  explicit IndexRing(uint32_t capacity) : capacity_(capacity), items_(new std::atomic<uint32_t>[capacity]) {}
  bool push(uint32_t v) {
    const uint64_t h = head_.load(std::memory_order_relaxed);
    if (h - tail_.load(std::memory_order_acquire) >= capacity_) return false;
    items_[h % capacity_].store(v, std::memory_order_relaxed);
    head_.store(h + 1, std::memory_order_release);
    return true;
  }
  bool pop(uint32_t& v) {
    const uint64_t t = tail_.load(std::memory_order_relaxed);
    if (t == head_.load(std::memory_order_acquire)) return false;
    v = items_[t % capacity_].load(std::memory_order_relaxed);
    tail_.store(t + 1, std::memory_order_release);
    return true;
  }

 private:
  const uint32_t capacity_;
  std::unique_ptr<std::atomic<uint32_t>[]> items_;
  alignas(64) std::atomic<uint64_t> head_{0};
  alignas(64) std::atomic<uint64_t> tail_{0};
};

template <typename T>
class DropOldestRing {
 public:
  // `init` is called once per slot (e.g. to size its image buffers).
  template <typename Init>
  DropOldestRing(uint32_t capacity, Init init)
      : capacity_(capacity),
        pool_size_(capacity + 2),
        pool_(new T[capacity + 2]),
        queue_(new std::atomic<uint32_t>[capacity]),
        free_(capacity + 2) {
    if (capacity == 0) throw std::invalid_argument("DropOldestRing: capacity must be at least 1");
    for (uint32_t i = 0; i < pool_size_; ++i) {
      init(pool_[i]);
      free_.push(i);
    }
  }
  explicit DropOldestRing(uint32_t capacity) : DropOldestRing(capacity, [](T&) {}) {}

  uint32_t capacity() const { return capacity_; }

  // ---- producer ----
  // The slot to fill next; stays the same until publish().
  T& writeSlot() {
    if (writing_ == kNone) {
      if (spare_ != kNone) {
        writing_ = spare_;
        spare_ = kNone;
      } else if (!free_.pop(writing_)) {
        // Cannot happen: pool = capacity + 2 covers the queue and both hands.
        throw std::logic_error("DropOldestRing: no free slot");
      }
    }
    return pool_[writing_];
  }
  // Queues the written slot. Returns true when the oldest queued item was dropped to make room.
  bool publish() {
    writeSlot();
    bool dropped = false;
    const uint64_t h = head_.load(std::memory_order_relaxed);
    uint64_t t = tail_.load(std::memory_order_acquire);
    while (h - t >= capacity_) {
      const uint32_t oldest = queue_[t % capacity_].load(std::memory_order_relaxed);
      if (tail_.compare_exchange_weak(t, t + 1, std::memory_order_acq_rel, std::memory_order_acquire)) {
        spare_ = oldest;  // we own it now: reuse it for the next write
        dropped = true;
        dropped_.fetch_add(1, std::memory_order_relaxed);
        break;
      }
    }
    queue_[h % capacity_].store(writing_, std::memory_order_relaxed);
    head_.store(h + 1, std::memory_order_release);
    writing_ = kNone;
    return dropped;
  }

  // ---- consumer ----
  // The oldest queued item, or nullptr when empty. Hold it until release().
  T* acquire() {
    if (reading_ != kNone) return &pool_[reading_];
    uint64_t t = tail_.load(std::memory_order_acquire);
    while (t != head_.load(std::memory_order_acquire)) {
      const uint32_t idx = queue_[t % capacity_].load(std::memory_order_relaxed);
      if (tail_.compare_exchange_weak(t, t + 1, std::memory_order_acq_rel, std::memory_order_acquire)) {
        reading_ = idx;
        return &pool_[idx];
      }
    }
    return nullptr;
  }
  void release() {
    if (reading_ == kNone) return;
    free_.push(reading_);
    reading_ = kNone;
  }

  // Either side.
  uint64_t size() const { return head_.load(std::memory_order_acquire) - tail_.load(std::memory_order_acquire); }
  uint64_t published() const { return head_.load(std::memory_order_relaxed); }
  uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }

 private:
  static constexpr uint32_t kNone = 0xFFFFFFFFu;
  const uint32_t capacity_;
  const uint32_t pool_size_;
  std::unique_ptr<T[]> pool_;
  std::unique_ptr<std::atomic<uint32_t>[]> queue_;
  IndexRing free_;
  alignas(64) std::atomic<uint64_t> head_{0};
  alignas(64) std::atomic<uint64_t> tail_{0};
  alignas(64) std::atomic<uint64_t> dropped_{0};
  // Producer-only and consumer-only state (on separate lines from the shared counters).
  alignas(64) uint32_t writing_ = kNone;
  uint32_t spare_ = kNone;
  alignas(64) uint32_t reading_ = kNone;
};

}  // namespace mcslam::platform
