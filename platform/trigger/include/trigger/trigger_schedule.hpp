#pragma once
// The pulse times of a fixed-rate trigger: pulse k is due at start + k * period. When the thread wakes
// too late to fire a pulse before the next one is due, the missed pulses are skipped (counted), so a
// hiccup never turns into a burst of pulses. Pure arithmetic; tested with made-up clocks.
#include <cstdint>

namespace mcslam::platform {

class TriggerSchedule {
 public:
  TriggerSchedule(int64_t start_ns, int64_t period_ns) : start_(start_ns), period_(period_ns) {}

  int64_t nextDeadline() const { return start_ + static_cast<int64_t>(slot_) * period_; }

  // Called when the thread woke at `now`: returns true when a pulse is to fire now; `missed` grows by
  // the pulses that were skipped because their time had fully passed.
  bool onWake(int64_t now_ns) {
    if (now_ns < nextDeadline()) return false;
    const uint64_t behind = static_cast<uint64_t>((now_ns - nextDeadline()) / period_);
    missed_ += behind;
    slot_ += behind + 1;
    return true;
  }
  uint64_t missed() const { return missed_; }

 private:
  int64_t start_, period_;
  uint64_t slot_ = 0;
  uint64_t missed_ = 0;
};

}  // namespace mcslam::platform
