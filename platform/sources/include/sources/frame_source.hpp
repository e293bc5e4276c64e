#pragma once
// Where images come from: GenICam cameras (aravis/), a recorded dataset (dataset_source), the simulator
// (sim_source). A source opens its devices in its constructor (throwing InputError naming the config key
// when one is unreachable), starts its own threads in start() and writes into the camera rings.
#include <atomic>
#include <cstddef>
#include <cstdint>

#include "realtime/warm_up.hpp"
#include "sources/back_pressure.hpp"
#include "sources/camera_rings.hpp"
#include "trigger/trigger_output.hpp"

namespace mcslam::platform {

struct SourceCounters {
  std::atomic<uint64_t> frames{0};       // images delivered into the rings
  std::atomic<uint64_t> bad_frames{0};   // incomplete buffers, wrong size, unreadable files
  std::atomic<uint64_t> lost_events{0};  // a camera stopped delivering (and was reopened)
};

// What a source is connected to while it runs; all of it outlives the source's threads.
struct SourceLinks {
  CameraRings* rings = nullptr;            // where the images go, one ring per camera
  const TriggerLog* triggers = nullptr;    // when each trigger fired (for the trigger-to-pose latency)
  const BackPressure* pressure = nullptr;  // a lossless replay waits on it
  const WarmUp* warm_up = nullptr;         // the source's allocation meters count once it is over
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // Starts the source's threads, which write into links.rings until stop().
  virtual void start(const SourceLinks& links) = 0;
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

 protected:
  SourceCounters counters_;
};

}  // namespace mcslam::platform
