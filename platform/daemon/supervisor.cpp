#include "daemon/supervisor.hpp"

#include <signal.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <utility>

#include <spdlog/spdlog.h>

#include "daemon/config_names.hpp"
#include "daemon/daemon.hpp"
#include "mcslam/core/alloc_counter.hpp"
#include "mcslam/core/background_task.hpp"
#include "mcslam/pipeline/pipeline_factory.hpp"
#include "realtime/scheduling.hpp"
#include "systemd/notifier.hpp"

namespace mcslam::platform {

namespace {

const char* unitNote(const DaemonStats& s) {
  if (!s.unscaled) return "";
  return s.roughly_metric
             ? " (roughly metric: too few of the cameras' common points are near enough for their baseline)"
             : " (up to scale)";
}

}  // namespace

void formatStatus(const DaemonStats& s, double rate_hz, const char* health, char* out, std::size_t size) {
  const double per_frame = s.frames_after_warmup ? static_cast<double>(s.allocations_after_warmup) /
                                                       static_cast<double>(s.frames_after_warmup)
                                                 : 0.0;
  std::snprintf(
      out, size,
      "%.1f Hz, %s%s, frames %llu, dropped %llu, partial %llu, latency p50 %.1f ms, allocs/frame %.2f%s, "
      "cameras %s%s, map %lld keyframes (culled %llu), relocalizations %llu, loop closures %llu, merges %llu, "
      "world revision %u, map saves %llu (failed %llu)",
      rate_hz, trackingStateName(s.tracking), unitNote(s), static_cast<unsigned long long>(s.processed),
      static_cast<unsigned long long>(s.rig_drops + s.camera_drops), static_cast<unsigned long long>(s.partial_frames),
      static_cast<double>(s.latency_p50_ns) * 1e-6, per_frame, s.warm ? "" : " (warming up)", health,
      s.source_finished ? ", source finished" : "", static_cast<long long>(s.places.keyframes),
      static_cast<unsigned long long>(s.places.keyframes_culled),
      static_cast<unsigned long long>(s.places.relocalizations),
      static_cast<unsigned long long>(s.places.loop_closures), static_cast<unsigned long long>(s.places.map_merges),
      static_cast<unsigned>(s.places.world_revision), static_cast<unsigned long long>(s.map_saves),
      static_cast<unsigned long long>(s.map_save_failures));
  if (s.shm_replacements == 0) return;
  const std::size_t used = std::strlen(out);
  if (used + 1 < size)
    std::snprintf(out + used, size - used, ", shm segments made anew %llu",
                  static_cast<unsigned long long>(s.shm_replacements));
}

namespace {

// A run of failures of an output (writes, sends) between two ticks, from its counters: worth one line when it
// begins and one when the output works again, not one per failure.
class FailureSpell {
 public:
  enum Change { Same, Began, Ended };
  Change update(uint64_t failures, uint64_t successes) {
    Change change = Same;
    if (failures > failures_ && !failing_) {
      change = Began;
      failing_ = true;
    } else if (failures == failures_ && successes > successes_ && failing_) {
      change = Ended;
      failing_ = false;
    }
    failures_ = failures;
    successes_ = successes;
    return change;
  }

 private:
  uint64_t failures_ = 0, successes_ = 0;
  bool failing_ = false;
};

// What the main loop watches between ticks: progress for the watchdog, and changes worth a log line.
class Watch {
 public:
  Watch(double status_interval_s, std::string trajectory_path)
      : trajectory_path_(std::move(trajectory_path)),
        status_ns_(static_cast<int64_t>(status_interval_s * 1e9)),
        last_progress_(monotonicNowNs()),
        last_status_(last_progress_) {}

  // One tick: the watchdog (only when frames were processed since the last tick, or a finished replay has
  // processed all it delivered and idles),
  // state changes, and the status line every status interval.
  void tick(const Daemon& daemon, SystemdNotifier& notifier) {
    const int64_t now = monotonicNowNs();
    const DaemonStats s = daemon.stats();
    char health[128];
    daemon.health(health, sizeof(health));
    watchdog(s, daemon.drained(), now, health, notifier);
    logChanges(s, health);
    logOutputs(s);
    if (now - last_status_ >= status_ns_) status(s, health, now, notifier);
  }

  void statusNow(const Daemon& daemon, SystemdNotifier& notifier) {
    char health[128];
    daemon.health(health, sizeof(health));
    status(daemon.stats(), health, monotonicNowNs(), notifier);
  }

 private:
  void status(const DaemonStats& s, const char* health, int64_t now, SystemdNotifier& notifier) {
    const double seconds = static_cast<double>(now - last_status_) * 1e-9;
    const double rate = seconds > 0 ? static_cast<double>(s.processed - processed_at_status_) / seconds : 0.0;
    char line[640];
    formatStatus(s, rate, health, line, sizeof(line));
    notifier.status(line);
    spdlog::info("{}", line);
    processed_at_status_ = s.processed;
    last_status_ = now;
  }

  // A replay that ended is idle only once its frames are processed: until then a hung pipeline must not be pinged.
  void watchdog(const DaemonStats& s, bool drained, int64_t now, const char* health, SystemdNotifier& notifier) {
    const bool progress = s.processed > last_processed_;
    const bool idle = s.source_finished && drained;
    if (progress) {
      last_progress_ = now;
      if (stall_reported_) spdlog::info("frames flow again");
      stall_reported_ = false;
    } else if (!idle && now - last_progress_ > 2000000000 && !stall_reported_) {
      spdlog::warn("no frame processed for 2 s (cameras: {})", health);
      stall_reported_ = true;
    }
    if (progress || idle) notifier.watchdog();
    last_processed_ = s.processed;
  }

  void logChanges(const DaemonStats& s, const char* health) {
    if (s.tracking != last_state_) {
      if (s.tracking == TrackingState::Lost)
        spdlog::warn("tracking lost (frame {})", s.processed);
      else
        spdlog::info("tracking state: {}{}", trackingStateName(s.tracking), unitNote(s));
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

  // The trajectory file's and the UDP sends' troubles, once when they begin and once when they end.
  void logOutputs(const DaemonStats& s) {
    const std::string& path = trajectory_path_;
    if (s.trajectory_reopened > trajectory_reopened_)
      spdlog::warn("trajectory {} was removed while being written: made again (the poses before are gone with it)",
                   path);
    trajectory_reopened_ = s.trajectory_reopened;
    switch (trajectory_.update(s.trajectory_errors, s.trajectory_poses)) {
      case FailureSpell::Began:
        spdlog::error("trajectory {}: poses cannot be written ({}); they are still published and are counted", path,
                      std::strerror(s.trajectory_errno));
        break;
      case FailureSpell::Ended:
        spdlog::info("trajectory {}: written again ({} poses missing from it so far)", path, s.trajectory_errors);
        break;
      case FailureSpell::Same: break;
    }
    switch (udp_.update(s.udp_failed, s.udp_sent)) {
      case FailureSpell::Began:
        spdlog::error("UDP: pose datagrams cannot be sent ({}); counted", std::strerror(s.udp_errno));
        break;
      case FailureSpell::Ended: spdlog::info("UDP: sending again ({} datagrams failed so far)", s.udp_failed); break;
      case FailureSpell::Same: break;
    }
  }

  std::string trajectory_path_;
  int64_t status_ns_;
  uint64_t last_processed_ = 0, processed_at_status_ = 0;
  int64_t last_progress_, last_status_;
  TrackingState last_state_ = TrackingState::NotInitialized;
  bool last_unscaled_ = false;
  uint64_t last_lost_ = 0;
  bool stall_reported_ = false;
  uint64_t trajectory_reopened_ = 0;
  FailureSpell trajectory_, udp_;
};

bool stopsTheDaemon(int sig) { return sig == SIGTERM || sig == SIGINT || sig == SIGQUIT; }

const char* signalName(int sig) {
  switch (sig) {
    case SIGTERM: return "SIGTERM";
    case SIGINT: return "SIGINT";
    case SIGQUIT: return "SIGQUIT";
    case SIGHUP: return "SIGHUP";
    case SIGUSR1: return "SIGUSR1";
    case SIGUSR2: return "SIGUSR2";
    default: return "a signal";
  }
}

// The signals the main thread takes (blocked in every thread, taken with sigtimedwait): whatever their default
// action, none of them ends the daemon without the clean stop (segment marked stopped, trajectory synced,
// extrinsics written).
sigset_t handledSignals() {
  sigset_t set;
  sigemptyset(&set);
  for (int sig : {SIGTERM, SIGINT, SIGQUIT, SIGHUP, SIGUSR1, SIGUSR2}) sigaddset(&set, sig);
  return set;
}

// A signal that does not stop the daemon: SIGUSR1 asks for the status line now; the others are logged and ignored
// (the configuration is read at start only).
void answerSignal(int sig, Watch& watch, const Daemon& daemon, SystemdNotifier& notifier) {
  if (sig == SIGUSR1) {
    watch.statusNow(daemon, notifier);
    return;
  }
  spdlog::warn(
      "{} ignored: mcslamd does not reload its configuration (restart it to apply a change; SIGTERM stops "
      "it, SIGUSR1 logs its status)",
      signalName(sig));
}

// Waits for a stopping signal (returned) or the end of a replay with at_end: exit (0), ticking the watch.
int superviseUntilStop(const DaemonConfig& config, const Daemon& daemon, SystemdNotifier& notifier,
                       const sigset_t& signals) {
  const int64_t status_ns = static_cast<int64_t>(config.status_interval_s * 1e9);
  const int64_t watchdog_ns = notifier.watchdogIntervalUs() * 1000 / 2;
  const int64_t tick_ns = watchdog_ns > 0 ? std::min(status_ns, watchdog_ns) : status_ns;
  Watch watch(config.status_interval_s, daemon.trajectoryPath());
  for (;;) {
    timespec timeout{static_cast<time_t>(tick_ns / 1000000000), static_cast<long>(tick_ns % 1000000000)};
    const int sig = sigtimedwait(&signals, nullptr, &timeout);
    if (sig > 0 && stopsTheDaemon(sig)) return sig;
    if (sig > 0) answerSignal(sig, watch, daemon, notifier);
    watch.tick(daemon, notifier);
    if (exitsAtEnd(config) && daemon.drained()) {
      spdlog::info("source finished (at_end: exit): stopping");
      return 0;
    }
  }
}

void restrictCpus(const std::vector<int>& cpus) {
  if (cpus.empty()) return;
  std::string list;
  for (const int cpu : cpus) list += (list.empty() ? "" : ", ") + std::to_string(cpu);
  if (const std::string why = restrictToCpus(cpus); !why.empty())
    spdlog::warn("realtime.cpus [{}]: {}; the threads run on any CPU", list, why);
  else
    spdlog::info("realtime: every thread on CPUs {}", list);
}

}  // namespace

int runDaemon(const DaemonConfig& config, std::unique_ptr<FrameProcessor> processor) {
  // Block the signals before any thread exists, so every thread inherits the mask and only this one receives
  // them (sigtimedwait).
  const sigset_t signals = handledSignals();
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  restrictCpus(config.realtime.cpus);                // before the pipeline's and the daemon's threads, which inherit it
  setBackgroundThreadSetup(&setUpBackgroundThread);  // before the pipeline's first background job
  SystemdNotifier notifier;
  if (!processor) processor = createPipeline(config.slam, config.file, config.rig, /*live=*/true);
  Daemon daemon(config, std::move(processor));
  daemon.start();
  notifier.ready();
  spdlog::info("mcslamd: running ({} cameras, source {}, trigger {}, trajectory {}){}", config.rig.size(),
               configName(config.source_type), configName(config.trigger.mode), daemon.trajectoryPath(),
               notifier.enabled() ? ", systemd notified" : "");
  const int signal_number = superviseUntilStop(config, daemon, notifier, signals);

  notifier.stopping();
  if (signal_number) spdlog::info("{}: stopping", signalName(signal_number));
  const bool clean = daemon.stop();
  const DaemonStats s = daemon.stats();
  spdlog::info(
      "stopped: {} frames processed, {} poses published, {} in the trajectory ({}), {} rig frames dropped, "
      "{} camera images dropped, {} partial, {} bad, trigger-to-pose latency p50 {:.1f} ms p99 {:.1f} ms, {} "
      "allocations in {} frames after warm-up (process total {})",
      s.processed, s.published, s.trajectory_poses, daemon.trajectoryPath(), s.rig_drops, s.camera_drops,
      s.partial_frames, s.bad_frames, static_cast<double>(s.latency_p50_ns) * 1e-6,
      static_cast<double>(s.latency_p99_ns) * 1e-6, s.allocations_after_warmup, s.frames_after_warmup,
      alloc::totalCount());
  const auto ms = [](int64_t ns) { return static_cast<double>(ns) * 1e-6; };
  spdlog::info(
      "stage times per frame, p50 / p99: front-end {:.1f} / {:.1f} ms, odometry {:.1f} / {:.1f} ms, place "
      "memory {:.1f} / {:.1f} ms",
      ms(s.front_end_time.p50_ns), ms(s.front_end_time.p99_ns), ms(s.odometry_time.p50_ns), ms(s.odometry_time.p99_ns),
      ms(s.place_memory_time.p50_ns), ms(s.place_memory_time.p99_ns));
  if (!clean) {
    // A thread is still inside the pipeline, and may never return: nothing it uses may be destroyed. The
    // trajectory of what was published is synced and the last periodic map save stands: the process ends here.
    spdlog::error("the pipeline did not finish its frame within the grace period: exiting with code 1 at once");
    spdlog::default_logger()->flush();
    std::fflush(nullptr);
    std::_Exit(1);
  }
  if (s.shm_replacements > 0)
    spdlog::warn("publish.shm: segments made anew after a truncation by another process: {}", s.shm_replacements);
  if (s.trajectory_errors > 0)
    spdlog::error("trajectory {}: {} poses or syncs failed (last: {}); the file holds whole lines only",
                  daemon.trajectoryPath(), s.trajectory_errors, std::strerror(s.trajectory_errno));
  return clean && s.trajectory_errors == 0 ? 0 : 1;
}

}  // namespace mcslam::platform
