#include <time.h>

#include "gpio/trigger_line.hpp"

namespace mcslam::platform {

bool PulseTrigger::fire(uint64_t) {
  const bool raised = line_.set(true);
  timespec ts{static_cast<time_t>(pulse_ns_ / 1000000000), static_cast<long>(pulse_ns_ % 1000000000)};
  clock_nanosleep(CLOCK_MONOTONIC, 0, &ts, nullptr);
  const bool lowered = line_.set(false);
  return raised && lowered;
}

}  // namespace mcslam::platform
