#include "daemon/daemon.hpp"

#include <spdlog/spdlog.h>

#include <filesystem>
#include <limits>

#include "daemon/source_factory.hpp"
#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/synced_file.hpp"
#include "realtime/scheduling.hpp"

namespace mcslam::platform {

static_assert(static_cast<int>(pose::Tracking::NotInitialized) == static_cast<int>(TrackingState::NotInitialized));
static_assert(static_cast<int>(pose::Tracking::Tracking) == static_cast<int>(TrackingState::Tracking));
static_assert(static_cast<int>(pose::Tracking::Lost) == static_cast<int>(TrackingState::Lost));
static_assert(static_cast<int>(pose::Tracking::Localizing) == static_cast<int>(TrackingState::Localizing));

namespace {
constexpr int64_t kMs = 1000000;

std::vector<std::pair<int, int>> imageSizes(const Rig& rig) {
  std::vector<std::pair<int, int>> s;
  for (int c = 0; c < rig.size(); ++c) s.emplace_back(rig.model(c).width(), rig.model(c).height());
  return s;
}

AssemblySettings assemblySettings(const DaemonConfig& c) {
  AssemblySettings a;
  a.pending_rig_frames = c.capacities.pending_rig_frames;
  a.match_by = c.assembly.match_by;
  a.tolerance_ns = static_cast<int64_t>(c.assembly.tolerance_ms * kMs);
  a.timeout_ns = static_cast<int64_t>(c.assembly.timeout_ms * kMs);
  a.priority = c.realtime.acquisition_priority;
  return a;
}
}  // namespace

Daemon::Daemon(const DaemonConfig& config, std::unique_ptr<FrameProcessor> processor,
               std::unique_ptr<FrameSource> source)
    : config_(config),
      processor_(std::move(processor)),
      source_(source ? std::move(source) : createSource(config)),
      sizes_(imageSizes(config.rig)),
      map_saver_(prepareMap(config, *processor_)),
      camera_rings_(sizes_, config.capacities.camera_ring_slots),
      rig_ring_(config.capacities.rig_ring_slots, [this](RigFrame& f) { f.allocate(sizes_); }),
      pose_ring_(config.capacities.pose_ring_slots),
      trigger_(config.trigger, config.realtime.trigger_priority, *source_, config.file),
      assembly_(sizes_, assemblySettings(config), camera_rings_, rig_ring_, warm_up_),
      processing_(*processor_, config.rig.size(), config.realtime.processing_priority,
                  static_cast<uint64_t>(config.warmup_frames), rig_ring_, pose_ring_, pressure_, warm_up_,
                  map_saver_.get()),
      publishing_(config, pose_ring_, warm_up_) {
  if (!config.output.extrinsics.empty()) extrinsics_path_ = outputPathFor(config, config.output.extrinsics);
  if (config.realtime.lock_memory) {
    if (const std::string why = lockAllMemory(); !why.empty()) spdlog::warn("realtime.lock_memory: {}", why);
  }
}

Daemon::~Daemon() {
  stop();
  // A frame that outlasted stop()'s grace period is still inside the pipeline, on threads that use this object's
  // members: they are released only once it is done. (mcslamd does not get here then: runDaemon ends the process.)
  if (!processing_.leftBehind() || processing_.finished()) return;
  spdlog::warn("daemon: waiting for the pipeline to finish its frame before releasing it");
  processing_.waitFinished(std::numeric_limits<int64_t>::max());
}

void Daemon::start() {
  if (started_) return;
  started_ = true;
  publishing_.start();
  if (map_saver_) map_saver_->start();
  processing_.start();
  assembly_.start();
  source_->start(SourceLinks{&camera_rings_, &trigger_.log(), &pressure_, &warm_up_});
  trigger_.start();
}

bool Daemon::stop(int64_t grace_ns) {
  if (!started_ || stopped_) return true;
  stopped_ = true;
  trigger_.stop();
  source_->stop();
  assembly_.stop();
  processing_.requestStop();
  const bool processing_finished = processing_.waitFinished(monotonicNowNs() + grace_ns);
  if (processing_finished)
    processing_.join();
  else
    processing_.detach();  // stuck inside the pipeline; we still save what was published
  publishing_.stop();
  if (processing_finished) {
    writeRefinedExtrinsics();  // else the pipeline may still be inside process()
    if (map_saver_) map_saver_->saveNow(*processor_);
  } else {
    if (!extrinsics_path_.empty()) spdlog::error("refined extrinsics not written: the pipeline did not stop");
    if (map_saver_) spdlog::error("map not saved at stop: the pipeline did not stop (the last periodic save stands)");
  }
  return processing_finished;
}

std::unique_ptr<MapSaver> Daemon::prepareMap(const DaemonConfig& config, FrameProcessor& processor) {
  const MapConfig& m = config.map;
  if (!m.load.empty()) {
    const std::string path = outputPathFor(config, m.load);
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) {
      if (m.localize_only) throw InputError("map.load: " + path + ": no such map to localize in (map.mode localize)");
      spdlog::info("map.load: no map at {} yet: this run starts one", path);
    } else {
      try {
        processor.loadMap(path, m.localize_only);
        spdlog::info("map.load: {} loaded{}: poses are in its frame once the rig is recognized in it", path,
                     m.localize_only ? " (localizing only)" : "");
      } catch (const InputError& e) {
        if (!m.start_without_unreadable) throw;
        // Kept for a post-mortem, and so that the next save does not overwrite it.
        const std::string aside = path + ".unreadable";
        std::filesystem::rename(path, aside, ec);
        spdlog::error("map.load: {}; starting without a map (map.on_unreadable: start_empty); the file is now {}",
                      e.what(), ec ? path + " (could not be renamed: " + ec.message() + ")" : aside);
      }
    }
  }
  if (m.save.empty()) return nullptr;
  return std::make_unique<MapSaver>(outputPathFor(config, m.save), m.save_interval_s, processor.maxMapBytes());
}

void Daemon::writeRefinedExtrinsics() {
  if (extrinsics_path_.empty()) return;
  Rig refined;
  if (!processor_->refinedRig(refined)) {
    spdlog::info("refined extrinsics: the pipeline provides none; nothing written");
    return;
  }
  std::string error;
  try {
    extrinsics_written_ = writeFileSynced(extrinsics_path_, formatKalibrRig(refined), &error);
  } catch (const std::exception& e) {
    error = e.what();
  }
  if (extrinsics_written_)
    spdlog::info("refined extrinsics written to {}", extrinsics_path_);
  else
    spdlog::error("output.extrinsics: {}", error);
}

// Approximate (the counters are read one after the other); stop() drains whatever is still in flight.
bool Daemon::drained() const {
  if (!source_->finished() || assembly_.assembler().pendingFrames() != 0 || rig_ring_.size() != 0 ||
      pose_ring_.size() != 0 || processing_.inFlight() != 0)
    return false;
  for (int c = 0; c < camera_rings_.cameras(); ++c)
    if (camera_rings_.ring(c).size() != 0) return false;
  return true;
}

DaemonStats Daemon::stats() const {
  DaemonStats s;
  s.triggers = trigger_.fired();
  s.trigger_failures = trigger_.failed();
  s.triggers_missed = trigger_.missed();
  const SourceCounters& sc = source_->counters();
  s.camera_frames = sc.frames.load();
  s.bad_frames = sc.bad_frames.load();
  s.lost_events = sc.lost_events.load();
  s.camera_drops = camera_rings_.dropped();
  s.rig_frames = assembly_.rigFrames();
  s.partial_frames = assembly_.assembler().partialFrames();
  s.late_images = assembly_.assembler().lateImages();
  s.rig_drops = assembly_.rigDrops();
  s.processed = processing_.processed();
  s.published = publishing_.published();
  s.pose_drops = processing_.poseDrops();
  s.udp_sent = publishing_.udp().sent();
  s.udp_failed = publishing_.udp().failed();
  s.udp_errno = publishing_.udp().lastErrno();
  s.trajectory_poses = publishing_.trajectory().written();
  s.trajectory_errors = publishing_.trajectory().errors();
  s.trajectory_reopened = publishing_.trajectory().reopened();
  s.shm_replacements = publishing_.shmReplacements();
  s.trajectory_errno = publishing_.trajectory().lastErrno();
  s.tracking = processing_.tracking();
  s.unscaled = processing_.unscaled();
  s.roughly_metric = processing_.roughlyMetric();
  s.latency_count = publishing_.latency().count();
  s.latency_p50_ns = publishing_.latency().percentileNs(0.5);
  s.latency_p99_ns = publishing_.latency().percentileNs(0.99);
  const auto percentiles = [](const LatencyHistogram& h) {
    return DaemonStats::StageTime{h.percentileNs(0.5), h.percentileNs(0.99)};
  };
  const StageTimes& t = processing_.stageTimes();
  s.front_end_time = percentiles(t.front_end);
  s.odometry_time = percentiles(t.odometry);
  s.place_memory_time = percentiles(t.place_memory);
  s.warm = warm_up_.warm();
  if (s.warm) {
    s.frames_after_warmup = s.processed - warm_up_.countAtEnd();
    s.allocations_after_warmup = assembly_.allocationsSinceWarmup() + processing_.allocationsSinceWarmup() +
                                 publishing_.allocationsSinceWarmup() + source_->allocationsSinceWarmup();
  }
  s.source_finished = source_->finished();
  s.places = processing_.placeCounters();
  if (map_saver_) {
    s.map_saves = map_saver_->saves();
    s.map_save_failures = map_saver_->failures();
    s.allocations_after_warmup += map_saver_->allocationsSinceWarmup();
  }
  return s;
}

}  // namespace mcslam::platform
