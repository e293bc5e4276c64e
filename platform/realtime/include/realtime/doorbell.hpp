#pragma once
// Wakes a waiting thread when there is new work, without locks or allocation (a Linux futex over a
// counter). ring() never blocks, so a producer that must not stall (the trigger, acquisition) can
// always call it.
#include <atomic>
#include <cstdint>

namespace mcslam::platform {

class Doorbell {
 public:
  // The counter value to wait on; read it before checking for work to not miss a ring.
  uint32_t ticket() const { return count_.load(std::memory_order_acquire); }
  void ring();
  // Returns when the counter differs from `ticket` or after timeout_ns (spurious returns possible).
  void wait(uint32_t ticket, int64_t timeout_ns) const;

 private:
  alignas(64) std::atomic<uint32_t> count_{0};
};

}  // namespace mcslam::platform
