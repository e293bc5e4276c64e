#pragma once
// Back-pressure from the pipeline to a lossless source (a dataset replay at rate fastest, the simulator at pace
// fastest): the consumer of the rig frames reports each frame it is done with; the source emits its next frame
// only while fewer than `window` of the frames it emitted are not done. A channel between two threads, like the
// rings: the daemon owns it and reports; the source holds it from start() to stop() and waits on it.
#include <atomic>
#include <cstdint>

#include "realtime/doorbell.hpp"

namespace mcslam::platform {

class BackPressure {
 public:
  // Two: one frame being processed while the next one waits for it.
  static constexpr uint64_t kWindow = 2;

  // Consumer: one more rig frame is done. Never blocks.
  void done() {
    done_.fetch_add(1, std::memory_order_release);
    bell_.ring();
  }
  uint64_t doneCount() const { return done_.load(std::memory_order_acquire); }

  // Source: waits until `emitted` (the frames it emitted so far) is below doneCount() + kWindow. Should a frame
  // vanish on the way (e.g. assembled together with another), goes on after `give_up_ns` rather than wait
  // forever. False when `stop` was set.
  bool waitForRoom(uint64_t emitted, const std::atomic<bool>& stop, int64_t give_up_ns = 2000000000) const;

 private:
  std::atomic<uint64_t> done_{0};
  Doorbell bell_;
};

}  // namespace mcslam::platform
