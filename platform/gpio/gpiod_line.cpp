#include "gpio/gpiod_line.hpp"

#include <gpiod.h>

#include <cerrno>
#include <cstring>

#include "mcslam/core/error.hpp"

namespace mcslam::platform {

GpiodLine::GpiodLine(const std::string& chip, int line, bool active_low, const std::string& consumer) {
  errno = 0;
  chip_ = gpiod_chip_open_lookup(chip.c_str());
  if (!chip_)
    throw InputError("trigger.gpio_chip: cannot open GPIO chip '" + chip + "': " +
                     (errno ? std::strerror(errno) : "not found") + " (is /dev/gpiochipN present and readable?)");
  const unsigned lines = gpiod_chip_num_lines(chip_);
  if (line < 0 || static_cast<unsigned>(line) >= lines) {
    gpiod_chip_close(chip_);
    throw InputError("trigger.gpio_line: line " + std::to_string(line) + " does not exist on '" + chip + "' (" +
                     std::to_string(lines) + " lines)");
  }
  line_ = gpiod_chip_get_line(chip_, static_cast<unsigned>(line));
  const int flags = active_low ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0;
  if (!line_ || gpiod_line_request_output_flags(line_, consumer.c_str(), flags, 0) != 0) {
    const std::string why = std::strerror(errno);
    gpiod_chip_close(chip_);
    throw InputError("trigger.gpio_line: cannot request line " + std::to_string(line) + " of '" + chip +
                     "' as an output: " + why);
  }
}

GpiodLine::~GpiodLine() {
  if (line_) {
    gpiod_line_set_value(line_, 0);
    gpiod_line_release(line_);
  }
  if (chip_) gpiod_chip_close(chip_);
}

bool GpiodLine::set(bool active) { return gpiod_line_set_value(line_, active ? 1 : 0) == 0; }

}  // namespace mcslam::platform
