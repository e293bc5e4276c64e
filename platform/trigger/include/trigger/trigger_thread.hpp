#pragma once
// The trigger thread: fires the output at the configured rate, on CLOCK_MONOTONIC absolute deadlines.
// It never waits on anything downstream; only the clock paces it.
#include <atomic>
#include <thread>

#include "trigger/trigger_output.hpp"

namespace mcslam::platform {

class TriggerThread {
 public:
  TriggerThread(TriggerOutput& output, TriggerLog& log, double rate_hz, int priority);
  ~TriggerThread() { stop(); }
  void start();
  void stop();
  uint64_t fired() const { return fired_.load(std::memory_order_relaxed); }
  uint64_t failed() const { return failed_.load(std::memory_order_relaxed); }
  uint64_t missed() const { return missed_.load(std::memory_order_relaxed); }

 private:
  void run();
  TriggerOutput& output_;
  TriggerLog& log_;
  int64_t period_ns_;
  int priority_;
  std::atomic<bool> stop_{false};
  std::atomic<uint64_t> fired_{0}, failed_{0}, missed_{0};
  std::thread thread_;
};

}  // namespace mcslam::platform
