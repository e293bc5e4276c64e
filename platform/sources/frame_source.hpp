#pragma once
// Where images come from: GenICam cameras (aravis/), a recorded dataset (dataset_source), later the
// simulator. A source opens its devices in its constructor (throwing InputError naming the config key
// when one is unreachable), starts its own threads in start() and writes into the camera rings.
#include <atomic>
#include <cstddef>
#include <cstdint>

#include "sources/camera_rings.hpp"
#include "trigger/trigger_output.hpp"

namespace mcslam::platform {

struct SourceCounters {
  std::atomic<uint64_t> frames{0};       // images delivered into the rings
  std::atomic<uint64_t> bad_frames{0};   // incomplete buffers, wrong size, unreadable files
  std::atomic<uint64_t> lost_events{0};  // a camera stopped delivering (and was reopened)
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual void start(CameraRings& rings, const TriggerLog& triggers) = 0;
  virtual void stop() = 0;
  // The software trigger (trigger.mode software), or nullptr when this source has none.
  virtual TriggerOutput* softwareTrigger() { return nullptr; }
  // Nothing more will come (a replay reached its end without looping).
  virtual bool finished() const { return false; }
  // One-line health summary for the status ("ok", "cam2 lost", ...), formatted into `out`.
  virtual void health(char* out, std::size_t size) const;
  // Heap allocations of the source's own threads since the warm-up ended.
  virtual uint64_t allocationsSinceWarmup() const = 0;
  const SourceCounters& counters() const { return counters_; }
  // Called by the daemon when the warm-up is over.
  void endWarmup() { warm_.store(true, std::memory_order_relaxed); }

 protected:
  bool warm() const { return warm_.load(std::memory_order_relaxed); }
  SourceCounters counters_;

 private:
  std::atomic<bool> warm_{false};
};

}  // namespace mcslam::platform
