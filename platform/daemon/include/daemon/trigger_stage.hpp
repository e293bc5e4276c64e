#pragma once
// The daemon's trigger: nothing (free-running), the software trigger of the source, or pulses on a GPIO line,
// fired by the trigger thread at trigger.rate_hz. Owns the trigger log that the sources read to trace a frame
// back to its trigger.
#include <memory>

#include "gpio/trigger_line.hpp"
#include "sources/frame_source.hpp"
#include "trigger/trigger_config.hpp"
#include "trigger/trigger_thread.hpp"

namespace mcslam::platform {

class TriggerStage {
 public:
  // Opens the GPIO line (trigger.mode gpio) or takes the source's software trigger (software). Throws
  // InputError naming `file` and the key when it cannot.
  TriggerStage(const TriggerConfig& config, int priority, FrameSource& source, const std::string& file);
  void start();
  void stop();
  const TriggerLog& log() const { return log_; }
  bool active() const { return thread_ != nullptr; }
  uint64_t fired() const { return thread_ ? thread_->fired() : 0; }
  uint64_t failed() const { return thread_ ? thread_->failed() : 0; }
  uint64_t missed() const { return thread_ ? thread_->missed() : 0; }

 private:
  TriggerLog log_;
  std::unique_ptr<TriggerLine> gpio_line_;
  std::unique_ptr<PulseTrigger> pulse_;
  std::unique_ptr<TriggerThread> thread_;
};

}  // namespace mcslam::platform
