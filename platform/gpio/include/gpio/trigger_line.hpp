#pragma once
// A digital output line, and the trigger output that pulses it. The GPIO adapter (gpiod_line.hpp)
// implements TriggerLine on real hardware; tests use a fake line.
#include <cstdint>

#include "trigger/trigger_output.hpp"

namespace mcslam::platform {

class TriggerLine {
 public:
  virtual ~TriggerLine() = default;
  // Drives the line to its active (true) or idle (false) level. False on failure.
  virtual bool set(bool active) = 0;
};

// One pulse per trigger: active for `pulse_ns`, then idle again (also when setting active failed, so
// the line never stays stuck active).
class PulseTrigger final : public TriggerOutput {
 public:
  PulseTrigger(TriggerLine& line, int64_t pulse_ns) : line_(line), pulse_ns_(pulse_ns) {}
  bool fire(uint64_t index) override;

 private:
  TriggerLine& line_;
  int64_t pulse_ns_;
};

}  // namespace mcslam::platform
