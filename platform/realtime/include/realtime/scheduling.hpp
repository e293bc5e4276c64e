#pragma once
// Thread names, realtime scheduling and memory locking (all optional, from the `realtime:` config).
#include <string>
#include <vector>

namespace mcslam::platform {

// Names the calling thread (shown by top -H and in /proc); at most 15 characters are kept.
void nameThisThread(const char* name);

// SCHED_FIFO at `priority` (1..99) for the calling thread; 0 leaves it as is. Returns an empty string
// on success, else the reason (e.g. missing CAP_SYS_NICE / LimitRTPRIO), which the caller logs.
std::string setRealtimePriority(int priority);

// SCHED_BATCH for the calling thread: it still gets its fair share of the CPU, but a wake-up of it no longer
// preempts the thread running (the frame's), which then finishes its frame first. For the core's background
// threads (mcslam::setBackgroundThreadSetup). Empty string on success, else the reason.
std::string useBatchScheduling();
// useBatchScheduling() as the core's background thread setup: logs the reason if it fails.
void setUpBackgroundThread();

// mlockall(MCL_CURRENT | MCL_FUTURE): no page faults on the hot path. Empty string on success.
std::string lockAllMemory();

// Pins the calling thread to one CPU (-1 = no pinning). Empty string on success.
std::string pinThisThread(int cpu);

// The highest CPU number an affinity set can name (CPU_SETSIZE - 1).
inline constexpr int kMaxCpuNumber = 1023;

// Lets the calling thread, and every thread it creates from now on, run only on `cpus` (0..kMaxCpuNumber; empty:
// no change). Empty string on success, else the reason (e.g. none of them is online).
std::string restrictToCpus(const std::vector<int>& cpus);

}  // namespace mcslam::platform
