#pragma once
// The `trigger:` section of mcslamd's configuration: what starts an exposure.
#include <string>

namespace mcslam::platform {

enum class TriggerMode {
  FreeRunning,  // the cameras (or the replay) run at their own rate
  Software,     // the trigger thread tells the source to capture (cameras' software trigger, the replay's next frame)
  Gpio,         // the trigger thread pulses a GPIO line wired to the cameras' trigger input
};

struct TriggerConfig {
  TriggerMode mode = TriggerMode::FreeRunning;
  double rate_hz = 20;
  std::string gpio_chip;  // gpiochipN, /dev/gpiochipN, label or number
  int gpio_line = -1;
  int pulse_us = 100;
  bool active_low = false;
};

}  // namespace mcslam::platform
