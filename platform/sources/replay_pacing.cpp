#include "sources/replay_pacing.hpp"

#include <time.h>

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

}  // namespace mcslam::platform
