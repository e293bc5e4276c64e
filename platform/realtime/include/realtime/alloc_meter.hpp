#pragma once
// Counts one thread's heap allocations after the warm-up: the thread calls note() after each item;
// once `counting` turns true the current count becomes the baseline. Others read since(). A count kept elsewhere
// (threads the meter's thread does not run) is metered the same way by handing it to note().
#include <atomic>
#include <cstdint>

#include "mcslam/core/alloc_counter.hpp"

namespace mcslam::platform {

class ThreadAllocMeter {
 public:
  void note(bool counting) { note(counting, alloc::threadCount()); }
  void note(bool counting, uint64_t now) {
    if (!based_.load(std::memory_order_relaxed)) {
      if (!counting) return;
      baseline_.store(now, std::memory_order_relaxed);
      based_.store(true, std::memory_order_release);
    }
    now_.store(now, std::memory_order_relaxed);
  }
  uint64_t since() const {
    if (!based_.load(std::memory_order_acquire)) return 0;
    return now_.load(std::memory_order_relaxed) - baseline_.load(std::memory_order_relaxed);
  }
  bool counting() const { return based_.load(std::memory_order_acquire); }

 private:
  std::atomic<uint64_t> baseline_{0}, now_{0};
  std::atomic<bool> based_{false};
};

}  // namespace mcslam::platform
