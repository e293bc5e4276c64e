#include "sources/replay_pacing.hpp"

#include <time.h>

#include "mcslam/core/time.hpp"

namespace mcslam::platform {

void sleepUntil(int64_t mono_ns) {
  timespec ts{static_cast<time_t>(mono_ns / 1000000000), static_cast<long>(mono_ns % 1000000000)};
  clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
}

bool waitForNewestTrigger(const std::atomic<bool>& stop, const std::atomic<uint64_t>& triggered, Doorbell& bell,
                          uint64_t served, uint64_t& newest) {
  while (!stop.load(std::memory_order_relaxed)) {
    const uint32_t ticket = bell.ticket();
    const uint64_t fired = triggered.load(std::memory_order_acquire);
    if (fired > served) {
      newest = fired - 1;
      return true;
    }
    bell.wait(ticket, 100000000);
  }
  return false;
}

bool waitForPipeline(const std::atomic<bool>& stop, const std::atomic<uint64_t>& emitted,
                     const std::atomic<uint64_t>& processed) {
  const int64_t give_up = monotonicNowNs() + 2000000000;
  while (!stop.load(std::memory_order_relaxed) &&
         emitted.load(std::memory_order_relaxed) >= processed.load(std::memory_order_acquire) + 2 &&
         monotonicNowNs() < give_up) {
    timespec ts{0, 200000};
    clock_nanosleep(CLOCK_MONOTONIC, 0, &ts, nullptr);
  }
  return !stop.load(std::memory_order_relaxed);
}

}  // namespace mcslam::platform
