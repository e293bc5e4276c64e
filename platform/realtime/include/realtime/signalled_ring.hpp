#pragma once
// A drop-oldest ring with the doorbell that wakes its consumer: the typed channel between two threads that
// must not wait for each other's pace. The producer never blocks (when the ring is full, publishing drops the
// oldest queued item, counted); the consumer sleeps until there is an item or it is told to stop.
#include <atomic>
#include <cstdint>

#include "realtime/doorbell.hpp"
#include "realtime/drop_oldest_ring.hpp"

namespace mcslam::platform {

template <typename T>
class SignalledRing {
 public:
  // `init` is called once per slot (e.g. to size its image buffers).
  template <typename Init>
  SignalledRing(uint32_t capacity, Init init) : ring_(capacity, init) {}
  explicit SignalledRing(uint32_t capacity) : ring_(capacity) {}

  // ---- producer ----
  T& slot() { return ring_.writeSlot(); }  // the slot to fill next; the same until publish()
  // Queues the slot and wakes the consumer. True when the oldest queued item was dropped to make room.
  bool publish() {
    const bool dropped = ring_.publish();
    bell_.ring();
    return dropped;
  }

  // ---- consumer ----
  // The oldest item, waiting for one; nullptr once `stop` is set and the ring is empty. Hold it until release().
  T* next(const std::atomic<bool>& stop) {
    for (;;) {
      const uint32_t ticket = bell_.ticket();
      if (T* item = ring_.acquire()) return item;
      if (stop.load(std::memory_order_relaxed)) return nullptr;
      bell_.wait(ticket, kPollNs);
    }
  }
  void release() { ring_.release(); }

  // Either side.
  void wake() { bell_.ring(); }  // after setting the consumer's stop flag
  uint64_t size() const { return ring_.size(); }
  uint64_t dropped() const { return ring_.dropped(); }

 private:
  static constexpr int64_t kPollNs = 50000000;  // a missed ring costs at most this
  DropOldestRing<T> ring_;
  Doorbell bell_;
};

}  // namespace mcslam::platform
