#include "daemon/supervisor.hpp"

#include <signal.h>

#include <algorithm>
#include <cstdio>

#include <spdlog/spdlog.h>

#include "daemon/config_names.hpp"
#include "daemon/daemon.hpp"
#include "mcslam/core/alloc_counter.hpp"
#include "mcslam/pipeline/pipeline_factory.hpp"
#include "systemd/notifier.hpp"

namespace mcslam::platform {

void formatStatus(const DaemonStats& s, double rate_hz, const char* health, char* out, std::size_t size) {
  const double per_frame = s.frames_after_warmup ? static_cast<double>(s.allocations_after_warmup) /
                                                       static_cast<double>(s.frames_after_warmup)
                                                 : 0.0;
  std::snprintf(
      out, size,
      "%.1f Hz, %s%s, frames %llu, dropped %llu, partial %llu, latency p50 %.1f ms, allocs/frame %.2f%s, "
      "cameras %s%s, map %lld keyframes (culled %llu), relocalizations %llu, loop closures %llu, merges %llu, "
      "world revision %u, map saves %llu (failed %llu)",
      rate_hz, trackingStateName(s.tracking), s.unscaled ? " (up to scale)" : "",
      static_cast<unsigned long long>(s.processed), static_cast<unsigned long long>(s.rig_drops + s.camera_drops),
      static_cast<unsigned long long>(s.partial_frames), static_cast<double>(s.latency_p50_ns) * 1e-6, per_frame,
      s.warm ? "" : " (warming up)", health, s.source_finished ? ", source finished" : "",
      static_cast<long long>(s.places.keyframes), static_cast<unsigned long long>(s.places.keyframes_culled),
      static_cast<unsigned long long>(s.places.relocalizations),
      static_cast<unsigned long long>(s.places.loop_closures), static_cast<unsigned long long>(s.places.map_merges),
      static_cast<unsigned>(s.places.world_revision), static_cast<unsigned long long>(s.map_saves),
      static_cast<unsigned long long>(s.map_save_failures));
}

namespace {

// What the main loop watches between ticks: progress for the watchdog, and changes worth a log line.
class Watch {
 public:
  explicit Watch(double status_interval_s)
      : status_ns_(static_cast<int64_t>(status_interval_s * 1e9)),
        last_progress_(monotonicNowNs()),
        last_status_(last_progress_) {}

  // One tick: the watchdog (only when frames were processed since the last tick, or a finished replay idles),
  // state changes, and the status line every status interval.
  void tick(const Daemon& daemon, SystemdNotifier& notifier) {
    const int64_t now = monotonicNowNs();
    const DaemonStats s = daemon.stats();
    char health[128];
    daemon.health(health, sizeof(health));
    watchdog(s, now, health, notifier);
    logChanges(s, health);
    if (now - last_status_ >= status_ns_) {
      const double rate =
          static_cast<double>(s.processed - processed_at_status_) / (static_cast<double>(now - last_status_) * 1e-9);
      char line[640];
      formatStatus(s, rate, health, line, sizeof(line));
      notifier.status(line);
      spdlog::info("{}", line);
      processed_at_status_ = s.processed;
      last_status_ = now;
    }
  }

 private:
  void watchdog(const DaemonStats& s, int64_t now, const char* health, SystemdNotifier& notifier) {
    const bool progress = s.processed > last_processed_;
    if (progress) {
      last_progress_ = now;
      if (stall_reported_) spdlog::info("frames flow again");
      stall_reported_ = false;
    } else if (!s.source_finished && now - last_progress_ > 2000000000 && !stall_reported_) {
      spdlog::warn("no frame processed for 2 s (cameras: {})", health);
      stall_reported_ = true;
    }
    if (progress || s.source_finished) notifier.watchdog();
    last_processed_ = s.processed;
  }

  void logChanges(const DaemonStats& s, const char* health) {
    if (s.tracking != last_state_) {
      if (s.tracking == TrackingState::Lost)
        spdlog::warn("tracking lost (frame {})", s.processed);
      else
        spdlog::info("tracking state: {}{}", trackingStateName(s.tracking), s.unscaled ? " (up to scale)" : "");
      last_state_ = s.tracking;
    } else if (last_unscaled_ && !s.unscaled && s.tracking == TrackingState::Tracking) {
      spdlog::info("metric scale found (by frame {}): positions are in metres from here on", s.processed);
    }
    last_unscaled_ = s.unscaled;
    if (s.lost_events > last_lost_) {
      spdlog::warn("camera lost events: {} ({})", s.lost_events, health);
      last_lost_ = s.lost_events;
    }
  }

  int64_t status_ns_;
  uint64_t last_processed_ = 0, processed_at_status_ = 0;
  int64_t last_progress_, last_status_;
  TrackingState last_state_ = TrackingState::NotInitialized;
  bool last_unscaled_ = false;
  uint64_t last_lost_ = 0;
  bool stall_reported_ = false;
};

// Waits for SIGTERM/SIGINT (returned) or the end of a replay with at_end: exit (0), ticking the watch.
int superviseUntilStop(const DaemonConfig& config, const Daemon& daemon, SystemdNotifier& notifier,
                       const sigset_t& stop_signals) {
  const int64_t status_ns = static_cast<int64_t>(config.status_interval_s * 1e9);
  const int64_t watchdog_ns = notifier.watchdogIntervalUs() * 1000 / 2;
  const int64_t tick_ns = watchdog_ns > 0 ? std::min(status_ns, watchdog_ns) : status_ns;
  Watch watch(config.status_interval_s);
  for (;;) {
    timespec timeout{static_cast<time_t>(tick_ns / 1000000000), static_cast<long>(tick_ns % 1000000000)};
    const int sig = sigtimedwait(&stop_signals, nullptr, &timeout);
    if (sig == SIGTERM || sig == SIGINT) return sig;
    watch.tick(daemon, notifier);
    if (exitsAtEnd(config) && daemon.drained()) {
      spdlog::info("source finished (at_end: exit): stopping");
      return 0;
    }
  }
}

}  // namespace

int runDaemon(const DaemonConfig& config) {
  // Block the stop signals before any thread exists, so every thread inherits the mask and only this
  // one receives them (sigtimedwait).
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGTERM);
  sigaddset(&stop_signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);

  SystemdNotifier notifier;
  Daemon daemon(config, createPipeline(config.slam, config.file, config.rig, /*live=*/true));
  daemon.start();
  notifier.ready();
  spdlog::info("mcslamd: running ({} cameras, source {}, trigger {}, trajectory {}){}", config.rig.size(),
               configName(config.source_type), configName(config.trigger.mode), daemon.trajectoryPath(),
               notifier.enabled() ? ", systemd notified" : "");
  const int signal_number = superviseUntilStop(config, daemon, notifier, stop_signals);

  notifier.stopping();
  if (signal_number) spdlog::info("{}: stopping", signal_number == SIGTERM ? "SIGTERM" : "SIGINT");
  const bool clean = daemon.stop();
  const DaemonStats s = daemon.stats();
  spdlog::info(
      "stopped: {} frames processed, {} poses published, {} in the trajectory ({}), {} rig frames dropped, "
      "{} camera images dropped, {} partial, {} bad, {} allocations in {} frames after warm-up (process total {})",
      s.processed, s.published, s.trajectory_poses, daemon.trajectoryPath(), s.rig_drops, s.camera_drops,
      s.partial_frames, s.bad_frames, s.allocations_after_warmup, s.frames_after_warmup, alloc::totalCount());
  if (!clean) spdlog::error("the pipeline did not finish its frame within the grace period");
  return clean ? 0 : 1;
}

}  // namespace mcslam::platform
