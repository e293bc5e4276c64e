#include "daemon/daemon.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include "daemon/synced_file.hpp"
#include "gpio/gpiod_line.hpp"
#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"
#include "realtime/scheduling.hpp"
#include "sources/source_factory.hpp"

namespace mcslam::platform {

static_assert(static_cast<int>(pose::Tracking::NotInitialized) == static_cast<int>(TrackingState::NotInitialized));
static_assert(static_cast<int>(pose::Tracking::Tracking) == static_cast<int>(TrackingState::Tracking));
static_assert(static_cast<int>(pose::Tracking::Lost) == static_cast<int>(TrackingState::Lost));

namespace {
constexpr int64_t kMs = 1000000;

std::vector<std::pair<int, int>> imageSizes(const Rig& rig) {
  std::vector<std::pair<int, int>> s;
  for (int c = 0; c < rig.size(); ++c) s.emplace_back(rig.model(c).width(), rig.model(c).height());
  return s;
}

std::vector<UdpDestination> destinationsOf(const DaemonConfig& c) {
  std::vector<UdpDestination> d;
  for (const auto& text : c.publish.udp_destinations)
    d.push_back(resolveUdpDestination(text, c.file + ": publish.udp.destinations"));
  return d;
}

int64_t realtimeNowNs() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}
}  // namespace

std::string outputPathFor(const DaemonConfig& c, const std::string& name) {
  std::string dir = c.output.directory;
  if (dir.empty()) {
    const char* state = std::getenv("STATE_DIRECTORY");  // systemd: StateDirectory=, maybe colon-separated
    if (state && *state) dir = std::string(state).substr(0, std::string(state).find(':'));
  }
  const std::filesystem::path base = dir.empty() ? std::filesystem::current_path() : std::filesystem::path(dir);
  return (base / name).string();
}

Daemon::Daemon(const DaemonConfig& config, std::unique_ptr<FrameProcessor> processor,
               std::unique_ptr<FrameSource> source)
    : config_(config), processor_(std::move(processor)),
      source_(source ? std::move(source) : createSource(config, processed_)), sizes_(imageSizes(config.rig)),
      camera_rings_(sizes_, config.capacities.camera_ring_slots),
      assembler_(sizes_, config.capacities.pending_rig_frames,
                 config.assembly.match_by == "timestamp" ? RigAssembler::MatchBy::Timestamp
                                                          : RigAssembler::MatchBy::TriggerCount,
                 static_cast<int64_t>(config.assembly.tolerance_ms * kMs),
                 static_cast<int64_t>(config.assembly.timeout_ms * kMs)),
      rig_ring_(config.capacities.rig_ring_slots, [this](RigFrame& f) { f.allocate(sizes_); }),
      pose_ring_(config.capacities.pose_ring_slots), views_(sizes_.size()), udp_(destinationsOf(config)) {
  staged_.resize(static_cast<std::size_t>(std::max(processor_->stageSlots(), 0)));
  if (config.publish.shm_enabled)
    shm_ = std::make_unique<PoseShmWriter>(config.publish.shm_name, config.publish.shm_ring_length,
                                           config.publish.shm_mode);
  const auto& t = config.trigger;
  if (t.mode == "gpio") {
    gpio_line_ = std::make_unique<GpiodLine>(t.gpio_chip, t.gpio_line, t.active_low);
    pulse_ = std::make_unique<PulseTrigger>(*gpio_line_, static_cast<int64_t>(t.pulse_us) * 1000);
    trigger_thread_ = std::make_unique<TriggerThread>(*pulse_, trigger_log_, t.rate_hz, config.realtime.trigger_priority);
  } else if (t.mode == "software") {
    TriggerOutput* out = source_->softwareTrigger();
    if (!out) throw InputError(config.file + ": trigger.mode: this source has no software trigger");
    trigger_thread_ = std::make_unique<TriggerThread>(*out, trigger_log_, t.rate_hz, config.realtime.trigger_priority);
  }
  trajectory_ = std::make_unique<TrajectoryWriter>(trajectoryPathFor(config));
  if (!config.output.extrinsics.empty()) extrinsics_path_ = outputPathFor(config, config.output.extrinsics);
  if (config.realtime.lock_memory) {
    if (const std::string why = lockAllMemory(); !why.empty()) spdlog::warn("realtime.lock_memory: {}", why);
  }
}

Daemon::~Daemon() { stop(); }

void Daemon::start() {
  if (started_) return;
  started_ = true;
  publishing_thread_ = std::thread([this] { publishingLoop(); });
  processing_thread_ = std::thread([this] { processingLoop(); });
  if (!staged_.empty()) features_thread_ = std::thread([this] { featuresLoop(); });
  assembly_thread_ = std::thread([this] { assemblyLoop(); });
  source_->start(camera_rings_, trigger_log_);
  if (trigger_thread_) trigger_thread_->start();
}

bool Daemon::stop(int64_t grace_ns) {
  if (!started_ || stopped_) return true;
  stopped_ = true;
  if (trigger_thread_) trigger_thread_->stop();
  source_->stop();
  stop_assembly_ = true;
  camera_rings_.bell().ring();
  assembly_thread_.join();
  stop_processing_ = true;
  rig_bell_.ring();
  const int64_t deadline = monotonicNowNs() + grace_ns;
  while (!processing_done_.load(std::memory_order_acquire) && monotonicNowNs() < deadline) {
    timespec ts{0, 5 * kMs};
    clock_nanosleep(CLOCK_MONOTONIC, 0, &ts, nullptr);
  }
  const bool processing_finished = processing_done_.load(std::memory_order_acquire);
  // The tracking stage ends after the features stage: both are done, or both are left behind.
  if (processing_finished) processing_thread_.join();
  else processing_thread_.detach();  // stuck inside the pipeline; we still save what was published
  if (features_thread_.joinable()) {
    if (processing_finished) features_thread_.join();
    else features_thread_.detach();
  }
  stop_publishing_ = true;
  pose_bell_.ring();
  publishing_thread_.join();
  trajectory_->close();  // fsync
  if (shm_) shm_->markStopped();
  if (processing_finished) writeRefinedExtrinsics();  // else the pipeline may still be inside process()
  else if (!extrinsics_path_.empty()) spdlog::error("refined extrinsics not written: the pipeline did not stop");
  return processing_finished;
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
  if (extrinsics_written_) spdlog::info("refined extrinsics written to {}", extrinsics_path_);
  else spdlog::error("output.extrinsics: {}", error);
}

bool Daemon::emitRigFrame(int64_t now, bool force) {
  RigFrame& out = rig_ring_.writeSlot();
  if (!assembler_.next(out, now, force)) return false;
  if (rig_ring_.publish()) rig_drops_.fetch_add(1, std::memory_order_relaxed);
  rig_frames_.fetch_add(1, std::memory_order_relaxed);
  rig_bell_.ring();
  return true;
}

void Daemon::assemblyLoop() {
  nameThisThread("mcslam-assemble");
  if (const auto why = setRealtimePriority(config_.realtime.acquisition_priority); !why.empty())
    spdlog::warn("assembly thread: {}", why);
  const int64_t poll = std::min<int64_t>(10 * kMs, static_cast<int64_t>(config_.assembly.timeout_ms * kMs / 2) + 1);
  while (!stop_assembly_.load(std::memory_order_relaxed)) {
    const uint32_t ticket = camera_rings_.bell().ticket();
    bool any = false;
    for (int c = 0; c < camera_rings_.cameras(); ++c) {
      auto& ring = camera_rings_.ring(c);
      while (CameraFrame* f = ring.acquire()) {
        while (!assembler_.add(c, *f, monotonicNowNs())) emitRigFrame(monotonicNowNs(), true);
        ring.release();
        any = true;
      }
    }
    while (emitRigFrame(monotonicNowNs(), false)) {
    }
    assembly_meter_.note(warm_.load(std::memory_order_relaxed));
    if (!any) camera_rings_.bell().wait(ticket, poll);
  }
  while (emitRigFrame(monotonicNowNs(), true)) {  // what was captured still goes out
  }
}

void Daemon::processingLoop() {
  nameThisThread("mcslam-process");
  if (const auto why = setRealtimePriority(config_.realtime.processing_priority); !why.empty())
    spdlog::warn("processing thread: {}", why);
  if (staged_.empty()) wholeFrameLoop();
  else trackingLoop();
  processing_done_.store(true, std::memory_order_release);
}

RigFrame* Daemon::nextRigFrame() {
  for (;;) {
    const uint32_t ticket = rig_bell_.ticket();
    if (RigFrame* f = rig_ring_.acquire()) return f;
    if (stop_processing_.load(std::memory_order_relaxed)) return nullptr;
    rig_bell_.wait(ticket, 50 * kMs);
  }
}

RigFrameView Daemon::viewOf(const RigFrame& f) {
  const int cameras = static_cast<int>(sizes_.size());
  for (int c = 0; c < cameras; ++c) views_[c] = f.images[c].view();
  return RigFrameView{f.capture_ns, f.sequence, cameras, views_.data(), f.present.get()};
}

void Daemon::wholeFrameLoop() {
  while (RigFrame* f = nextRigFrame()) {
    PoseSlot& out = pose_ring_.writeSlot();
    processor_->process(viewOf(*f), out.estimate);
    out.trigger_mono_ns = f->trigger_mono_ns;
    out.cameras_present = f->presentCount();
    rig_ring_.release();
    handOver(out);
  }
}

void Daemon::featuresLoop() {
  nameThisThread("mcslam-features");
  if (const auto why = setRealtimePriority(config_.realtime.processing_priority); !why.empty())
    spdlog::warn("features thread: {}", why);
  const uint64_t slots = staged_.size();
  while (RigFrame* f = nextRigFrame()) {
    // A free slot (tracking finishes them in order); meanwhile new rig frames queue, and the oldest is
    // dropped when the rig ring is full, as without stages.
    for (;;) {
      const uint32_t free_ticket = stage_free_bell_.ticket();
      if (staged_head_.load(std::memory_order_relaxed) - staged_tail_.load(std::memory_order_acquire) < slots) break;
      stage_free_bell_.wait(free_ticket, 50 * kMs);
    }
    const uint64_t head = staged_head_.load(std::memory_order_relaxed);
    const int slot = static_cast<int>(head % slots);
    processor_->prepare(viewOf(*f), slot);
    staged_[static_cast<std::size_t>(slot)] = StagedFrame{f->trigger_mono_ns, f->presentCount()};
    rig_ring_.release();
    staged_head_.store(head + 1, std::memory_order_release);
    staged_bell_.ring();
    features_meter_.note(warm_.load(std::memory_order_relaxed));
  }
  features_done_.store(true, std::memory_order_release);
  staged_bell_.ring();
}

void Daemon::trackingLoop() {
  const uint64_t slots = staged_.size();
  for (;;) {
    const uint32_t ticket = staged_bell_.ticket();
    const uint64_t tail = staged_tail_.load(std::memory_order_relaxed);
    if (staged_head_.load(std::memory_order_acquire) == tail) {
      // features_done_ is set after the last prepared frame: read it first, then look again.
      if (features_done_.load(std::memory_order_acquire) && staged_head_.load(std::memory_order_acquire) == tail) break;
      staged_bell_.wait(ticket, 50 * kMs);
      continue;
    }
    const int slot = static_cast<int>(tail % slots);
    PoseSlot& out = pose_ring_.writeSlot();
    processor_->finish(slot, out.estimate);
    out.trigger_mono_ns = staged_[static_cast<std::size_t>(slot)].trigger_mono_ns;
    out.cameras_present = staged_[static_cast<std::size_t>(slot)].cameras_present;
    staged_tail_.store(tail + 1, std::memory_order_release);
    stage_free_bell_.ring();
    handOver(out);
  }
}

void Daemon::handOver(PoseSlot& out) {
  const uint64_t warmup = static_cast<uint64_t>(config_.warmup_frames);
  if (pose_ring_.publish()) pose_drops_.fetch_add(1, std::memory_order_relaxed);
  pose_bell_.ring();
  tracking_.store(static_cast<uint8_t>(out.estimate.state), std::memory_order_relaxed);
  unscaled_.store(out.estimate.valid && !out.estimate.metric, std::memory_order_relaxed);
  const uint64_t done = processed_.fetch_add(1, std::memory_order_release) + 1;
  if (!warm_.load(std::memory_order_relaxed) && done >= warmup) {
    processed_at_warmup_.store(done, std::memory_order_relaxed);
    warm_.store(true, std::memory_order_release);
    source_->endWarmup();
  }
  processing_meter_.note(warm_.load(std::memory_order_relaxed));
}

void Daemon::publishPose(const PoseSlot& slot) {
  const PoseEstimate& e = slot.estimate;
  pose::PoseRecord r;
  r.sequence = ++sequence_;
  r.frame_sequence = e.sequence;
  r.capture_time_ns = e.t;
  r.publish_time_ns = realtimeNowNs();
  const Eigen::Quaterniond q = e.T_w_b.quaternion();
  for (int i = 0; i < 3; ++i) r.position[i] = e.T_w_b.t[i];
  r.orientation[0] = q.x();
  r.orientation[1] = q.y();
  r.orientation[2] = q.z();
  r.orientation[3] = q.w();
  r.tracking = static_cast<pose::Tracking>(e.state);
  r.flags = static_cast<uint8_t>((e.valid ? pose::kFlagValid : 0) | (e.is_keyframe ? pose::kFlagKeyframe : 0) |
                                 (e.metric ? 0 : pose::kFlagUnscaled));
  r.quality = e.quality;
  if (shm_) shm_->publish(r);
  udp_.send(r);
  if (slot.trigger_mono_ns > 0) latency_.record(monotonicNowNs() - slot.trigger_mono_ns);
  if (r.valid()) trajectory_->append(r);
  published_.store(r.sequence, std::memory_order_release);
}

void Daemon::publishingLoop() {
  nameThisThread("mcslam-publish");
  for (;;) {
    const uint32_t ticket = pose_bell_.ticket();
    PoseSlot* s = pose_ring_.acquire();
    if (!s) {
      if (stop_publishing_.load(std::memory_order_relaxed)) break;
      pose_bell_.wait(ticket, 50 * kMs);
      continue;
    }
    publishPose(*s);
    pose_ring_.release();
    publishing_meter_.note(warm_.load(std::memory_order_relaxed));
  }
}

// Approximate (the counters are read one after the other); stop() drains whatever is still in flight.
bool Daemon::drained() const {
  if (!source_->finished() || assembler_.pendingFrames() != 0 || rig_ring_.size() != 0 || pose_ring_.size() != 0)
    return false;
  if (staged_head_.load() != staged_tail_.load()) return false;
  for (int c = 0; c < camera_rings_.cameras(); ++c)
    if (camera_rings_.ring(c).size() != 0) return false;
  return true;
}

DaemonStats Daemon::stats() const {
  DaemonStats s;
  if (trigger_thread_) {
    s.triggers = trigger_thread_->fired();
    s.trigger_failures = trigger_thread_->failed();
    s.triggers_missed = trigger_thread_->missed();
  }
  const SourceCounters& sc = source_->counters();
  s.camera_frames = sc.frames.load();
  s.bad_frames = sc.bad_frames.load();
  s.lost_events = sc.lost_events.load();
  s.camera_drops = camera_rings_.dropped();
  s.rig_frames = rig_frames_.load();
  s.partial_frames = assembler_.partialFrames();
  s.late_images = assembler_.lateImages();
  s.rig_drops = rig_drops_.load();
  s.processed = processed_.load();
  s.published = published_.load();
  s.pose_drops = pose_drops_.load();
  s.udp_sent = udp_.sent();
  s.udp_failed = udp_.failed();
  s.trajectory_poses = trajectory_->written();
  s.trajectory_errors = trajectory_->errors();
  s.tracking = static_cast<TrackingState>(tracking_.load());
  s.unscaled = unscaled_.load();
  s.latency_count = latency_.count();
  s.latency_p50_ns = latency_.percentileNs(0.5);
  s.latency_p99_ns = latency_.percentileNs(0.99);
  s.warm = warm_.load();
  if (s.warm) {
    s.frames_after_warmup = s.processed - processed_at_warmup_.load();
    s.allocations_after_warmup = assembly_meter_.since() + features_meter_.since() + processing_meter_.since() +
                                 publishing_meter_.since() + source_->allocationsSinceWarmup();
  }
  s.source_finished = source_->finished();
  return s;
}

}  // namespace mcslam::platform
