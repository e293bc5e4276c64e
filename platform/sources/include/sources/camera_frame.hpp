#pragma once
// One image from one camera, as a source writes it into its camera's ring (acquisition -> assembly). Its
// image buffer is sized at start-up; the assembly swaps buffers instead of copying.
#include <cstdint>

#include "mcslam/core/image.hpp"
#include "mcslam/core/time.hpp"

namespace mcslam::platform {

struct CameraFrame {
  Image image;
  Timestamp capture_ns = 0;     // time base of the trajectory (dataset stamps, or host CLOCK_REALTIME)
  uint64_t trigger_index = 0;   // which trigger (or frame number) produced it
  int64_t trigger_mono_ns = 0;  // CLOCK_MONOTONIC of the trigger (or of the arrival when free-running)
};

}  // namespace mcslam::platform
