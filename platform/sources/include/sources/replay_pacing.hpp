#pragma once
// Waits shared by the sources that replay frames from a thread of their own (dataset, sim). The lossless
// modes wait on the pipeline's BackPressure.
#include <atomic>
#include <cstdint>

#include "realtime/doorbell.hpp"

namespace mcslam::platform {

// Sleeps until the CLOCK_MONOTONIC time mono_ns.
void sleepUntil(int64_t mono_ns);

// Software trigger: waits for a trigger after the first `served` ones and gives the newest (like a busy camera,
// a replay skips the triggers it could not keep up with). False when stopping.
bool waitForNewestTrigger(const std::atomic<bool>& stop, const std::atomic<uint64_t>& triggered, Doorbell& bell,
                          uint64_t served, uint64_t& newest);

}  // namespace mcslam::platform
