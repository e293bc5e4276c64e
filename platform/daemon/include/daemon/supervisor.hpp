#pragma once
// The daemon's main thread: builds the Daemon, tells systemd READY=1, then until SIGTERM/SIGINT/SIGQUIT (or the
// end of a replay with at_end: exit) sends STATUS= and WATCHDOG=1 (only while frames are being
// processed), logs statistics and state changes, and finally stops everything within 2 s.
#include <memory>

#include "daemon/daemon_config.hpp"
#include "mcslam/pipeline/frame_processor.hpp"

namespace mcslam::platform {

// Returns the process exit code: 0 after a clean stop, 1 after a clean stop that lost trajectory writes. When the
// pipeline did not finish its frame within the grace period, ends the process at once with code 1 (std::_Exit):
// its thread cannot be joined, and what it uses must not be destroyed under it.
// Throws InputError when start-up fails (before any thread starts). `processor`: the pipeline the configuration
// describes when null (tests give their own).
int runDaemon(const DaemonConfig& config, std::unique_ptr<FrameProcessor> processor = nullptr);

// Formats one status line ("20.0 Hz, tracking, frames 1234, dropped 0, allocs/frame 0.00").
struct DaemonStats;
void formatStatus(const DaemonStats& s, double rate_hz, const char* health, char* out, std::size_t size);

}  // namespace mcslam::platform
