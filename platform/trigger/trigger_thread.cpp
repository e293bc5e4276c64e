#include "trigger/trigger_thread.hpp"

#include <time.h>

#include <algorithm>

#include <spdlog/spdlog.h>

#include "mcslam/core/time.hpp"
#include "realtime/scheduling.hpp"
#include "trigger/trigger_schedule.hpp"

namespace mcslam::platform {

TriggerThread::TriggerThread(TriggerOutput& output, TriggerLog& log, double rate_hz, int priority)
    : output_(output), log_(log), period_ns_(static_cast<int64_t>(1e9 / rate_hz)), priority_(priority) {}

void TriggerThread::start() {
  stop_ = false;
  thread_ = std::thread([this] { run(); });
}

void TriggerThread::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void TriggerThread::run() {
  nameThisThread("mcslam-trigger");
  if (const std::string why = setRealtimePriority(priority_); !why.empty()) spdlog::warn("trigger thread: {}", why);
  TriggerSchedule schedule(monotonicNowNs() + period_ns_, period_ns_);
  uint64_t index = 0;
  while (!stop_.load(std::memory_order_relaxed)) {
    // Sleep to the deadline, but at most 100 ms at a time so that stop() is prompt at low rates.
    const int64_t deadline = std::min(schedule.nextDeadline(), monotonicNowNs() + 100000000);
    timespec ts{static_cast<time_t>(deadline / 1000000000), static_cast<long>(deadline % 1000000000)};
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
    const int64_t now = monotonicNowNs();
    if (!schedule.onWake(now)) continue;
    missed_.store(schedule.missed(), std::memory_order_relaxed);
    log_.record(index, now);
    if (output_.fire(index))
      fired_.fetch_add(1, std::memory_order_relaxed);
    else
      failed_.fetch_add(1, std::memory_order_relaxed);
    ++index;
  }
}

}  // namespace mcslam::platform
