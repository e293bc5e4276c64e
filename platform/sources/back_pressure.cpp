#include "sources/back_pressure.hpp"

#include <algorithm>

#include "mcslam/core/time.hpp"

namespace mcslam::platform {

bool BackPressure::waitForRoom(uint64_t emitted, const std::atomic<bool>& stop, int64_t give_up_ns) const {
  const int64_t give_up = monotonicNowNs() + give_up_ns;
  for (;;) {
    if (stop.load(std::memory_order_relaxed)) return false;
    const uint32_t ticket = bell_.ticket();
    if (emitted < doneCount() + kWindow) return true;
    const int64_t now = monotonicNowNs();
    if (now >= give_up) return true;
    bell_.wait(ticket, std::min<int64_t>(give_up - now, 20000000));  // wakes every 20 ms to notice a stop
  }
}

}  // namespace mcslam::platform
