#pragma once
// The end of the warm-up, after which every thread's allocation meter counts (ThreadAllocMeter::note(warm())).
// One thread decides (the daemon's processing, after so many frames); any thread reads.
#include <atomic>
#include <cstdint>

namespace mcslam::platform {

class WarmUp {
 public:
  bool warm() const { return warm_.load(std::memory_order_acquire); }
  // The warm-up ends after `count` items (frames) of the deciding thread.
  void end(uint64_t count) {
    count_.store(count, std::memory_order_relaxed);
    warm_.store(true, std::memory_order_release);
  }
  uint64_t countAtEnd() const { return count_.load(std::memory_order_relaxed); }

 private:
  std::atomic<bool> warm_{false};
  std::atomic<uint64_t> count_{0};
};

}  // namespace mcslam::platform
