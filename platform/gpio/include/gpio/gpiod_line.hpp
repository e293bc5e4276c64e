#pragma once
// A GPIO output line through libgpiod 1.6 (the character device /dev/gpiochipN).
#include <string>

#include "gpio/trigger_line.hpp"

struct gpiod_chip;
struct gpiod_line;

namespace mcslam::platform {

class GpiodLine final : public TriggerLine {
 public:
  // chip: "gpiochip0", "/dev/gpiochip0", a label or a number. Requests `line` as an output at its idle
  // level. Throws InputError naming the config keys (trigger.gpio_chip / trigger.gpio_line), the value
  // and the reason when the chip is missing, the line does not exist or is busy.
  GpiodLine(const std::string& chip, int line, bool active_low, const std::string& consumer = "mcslamd");
  ~GpiodLine() override;
  GpiodLine(const GpiodLine&) = delete;
  GpiodLine& operator=(const GpiodLine&) = delete;

  bool set(bool active) override;

 private:
  gpiod_chip* chip_ = nullptr;
  gpiod_line* line_ = nullptr;
};

}  // namespace mcslam::platform
