#pragma once
// What a trigger pulse does: toggle a GPIO line, send a software trigger to the cameras, or tell the
// dataset replay to emit its next frame. Called from the trigger thread only.
#include <atomic>
#include <cstdint>

namespace mcslam::platform {

class TriggerOutput {
 public:
  virtual ~TriggerOutput() = default;
  // Fires trigger number `index` (0, 1, 2, ...). Returns false when it failed (counted by the caller).
  virtual bool fire(uint64_t index) = 0;
};

// Remembers when each recent trigger fired (CLOCK_MONOTONIC), so the frame it produced can be traced
// back to it for the trigger-to-pose latency. Fixed ring; lock-free; one writer.
class TriggerLog {
 public:
  static constexpr uint32_t kSize = 4096;
  void record(uint64_t index, int64_t mono_ns) {
    entries_[index % kSize].index.store(index, std::memory_order_relaxed);
    entries_[index % kSize].mono_ns.store(mono_ns, std::memory_order_release);
    count_.store(index + 1, std::memory_order_release);
  }
  // The newest trigger fired at or before `mono_ns` (a camera's frame belongs to it): false when none.
  bool latestAtOrBefore(int64_t mono_ns, uint64_t& index, int64_t& fired_ns) const {
    const uint64_t n = count_.load(std::memory_order_acquire);
    for (uint64_t back = 0; back < n && back < 64; ++back) {
      const uint64_t i = n - 1 - back;
      const int64_t t = lookup(i);
      if (t != 0 && t <= mono_ns) {
        index = i;
        fired_ns = t;
        return true;
      }
    }
    return false;
  }
  // 0 when that trigger is unknown or already overwritten.
  int64_t lookup(uint64_t index) const {
    const Entry& e = entries_[index % kSize];
    const int64_t t = e.mono_ns.load(std::memory_order_acquire);
    return e.index.load(std::memory_order_relaxed) == index ? t : 0;
  }

 private:
  struct Entry {
    std::atomic<uint64_t> index{~0ull};
    std::atomic<int64_t> mono_ns{0};
  };
  Entry entries_[kSize];
  std::atomic<uint64_t> count_{0};
};

}  // namespace mcslam::platform
