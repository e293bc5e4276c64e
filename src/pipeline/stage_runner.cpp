#include "mcslam/pipeline/stage_runner.hpp"

#include <algorithm>

namespace mcslam {

StageSlots::StageSlots(FrameProcessor& processor)
    : processor_(processor),
      staged_(processor.stageSlots() > 0),
      poses_(static_cast<std::size_t>(std::max(processor.stageSlots(), 1))) {}

void StageSlots::signal() {
  changes_.fetch_add(1, std::memory_order_release);
  changes_.notify_all();
}

void StageSlots::close() {
  closed_.store(true, std::memory_order_release);
  signal();
}

int StageSlots::reserve() {
  const uint64_t head = prepared_.load(std::memory_order_relaxed);  // only this thread moves it
  for (;;) {
    const uint32_t seen = changes_.load(std::memory_order_acquire);
    if (head - finished_.load(std::memory_order_acquire) < poses_.size()) break;
    changes_.wait(seen, std::memory_order_acquire);
  }
  return static_cast<int>(head % poses_.size());
}

void StageSlots::prepare(int slot, const RigFrameView& frame) {
  if (staged_)
    processor_.prepare(frame, slot);
  else
    processor_.process(frame, poses_[static_cast<std::size_t>(slot)]);
  prepared_.fetch_add(1, std::memory_order_release);
  signal();
}

int StageSlots::next() {
  const uint64_t tail = finished_.load(std::memory_order_relaxed);  // only this thread moves it
  for (;;) {
    const uint32_t seen = changes_.load(std::memory_order_acquire);
    if (prepared_.load(std::memory_order_acquire) != tail) break;
    // closed_ is set after the last frame was prepared: read it, then look at the count again.
    if (closed_.load(std::memory_order_acquire) && prepared_.load(std::memory_order_acquire) == tail) return -1;
    changes_.wait(seen, std::memory_order_acquire);
  }
  return static_cast<int>(tail % poses_.size());
}

void StageSlots::finish(int slot, PoseEstimate& out) {
  if (staged_)
    processor_.finish(slot, out);
  else
    out = poses_[static_cast<std::size_t>(slot)];
  finished_.fetch_add(1, std::memory_order_release);
  signal();
}

}  // namespace mcslam
