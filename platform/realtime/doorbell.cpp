#include "realtime/doorbell.hpp"

#include <linux/futex.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

namespace mcslam::platform {

void Doorbell::ring() {
  count_.fetch_add(1, std::memory_order_release);
  ::syscall(SYS_futex, reinterpret_cast<uint32_t*>(&count_), FUTEX_WAKE_PRIVATE, INT32_MAX, nullptr, nullptr, 0);
}

void Doorbell::wait(uint32_t ticket, int64_t timeout_ns) const {
  if (count_.load(std::memory_order_acquire) != ticket) return;
  timespec ts{static_cast<time_t>(timeout_ns / 1000000000), static_cast<long>(timeout_ns % 1000000000)};
  ::syscall(SYS_futex, reinterpret_cast<const uint32_t*>(&count_), FUTEX_WAIT_PRIVATE, ticket, &ts, nullptr, 0);
}

}  // namespace mcslam::platform
