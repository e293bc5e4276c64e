#include "daemon/processing_stage.hpp"

#include <spdlog/spdlog.h>

#include <time.h>

#include "mcslam/core/time.hpp"
#include "realtime/scheduling.hpp"

namespace mcslam::platform {

ProcessingStage::ProcessingStage(FrameProcessor& processor, int cameras, int priority, uint64_t warmup_frames,
                                 RigRing& in, PoseRing& out, BackPressure& pressure, WarmUp& warm_up,
                                 MapSaver* map_saver)
    : processor_(processor),
      map_saver_(map_saver),
      runner_(processor),
      priority_(priority),
      warmup_frames_(warmup_frames),
      in_(in),
      out_(out),
      pressure_(pressure),
      warm_up_(warm_up),
      views_(static_cast<std::size_t>(cameras)) {}

void ProcessingStage::start() {
  processing_thread_ = std::thread([this] {
    setUpThread("mcslam-process", "processing");
    if (runner_.canOverlap())
      trackingLoop();
    else
      wholeLoop();
    done_.store(true, std::memory_order_release);
  });
  if (runner_.canOverlap()) {
    features_done_.store(false, std::memory_order_release);
    try {
      features_thread_ = std::thread([this] {
        setUpThread("mcslam-features", "features");
        featuresLoop();
        features_done_.store(true, std::memory_order_release);  // after close(): done with the runner
      });
    } catch (...) {  // no features thread: the tracking thread would wait for its frames for ever
      features_done_.store(true, std::memory_order_release);
      runner_.close();
      processing_thread_.join();
      throw;
    }
  }
}

void ProcessingStage::requestStop() {
  stop_ = true;
  in_.wake();
}

// The tracking stage ends after the features stage: both are done, or both are left behind.
void ProcessingStage::join() {
  if (processing_thread_.joinable()) processing_thread_.join();
  if (features_thread_.joinable()) features_thread_.join();
}

bool ProcessingStage::waitFinished(int64_t deadline_ns) const {
  while (!finished() && monotonicNowNs() < deadline_ns) {
    timespec ts{0, 5000000};
    clock_nanosleep(CLOCK_MONOTONIC, 0, &ts, nullptr);
  }
  return finished();
}

void ProcessingStage::detach() {
  left_behind_ = processing_thread_.joinable() || features_thread_.joinable();
  if (processing_thread_.joinable()) processing_thread_.detach();
  if (features_thread_.joinable()) features_thread_.detach();
}

void ProcessingStage::setUpThread(const char* name, const char* role) {
  nameThisThread(name);
  if (const auto why = setRealtimePriority(priority_); !why.empty()) spdlog::warn("{} thread: {}", role, why);
}

RigFrameView ProcessingStage::viewOf(const RigFrame& f) {
  const int cameras = static_cast<int>(views_.size());
  for (int c = 0; c < cameras; ++c) views_[c] = f.images[c].view();
  return RigFrameView{f.capture_ns, f.sequence, cameras, views_.data(), f.present.get()};
}

void ProcessingStage::wholeLoop() {
  FrameTag tag;
  while (RigFrame* f = in_.next(stop_)) {
    taken_.fetch_add(1, std::memory_order_relaxed);
    runner_.prepare(viewOf(*f), FrameTag{f->trigger_mono_ns, f->presentCount()});
    in_.release();
    PoseSlot& out = out_.slot();
    runner_.finish(out.estimate, tag);
    handOver(out, tag);
  }
}

void ProcessingStage::featuresLoop() {
  // prepare() waits for a free slot (tracking finishes them in order); meanwhile new rig frames queue, and the
  // oldest is dropped when the rig ring is full, as without stages.
  while (RigFrame* f = in_.next(stop_)) {
    taken_.fetch_add(1, std::memory_order_relaxed);
    runner_.prepare(viewOf(*f), FrameTag{f->trigger_mono_ns, f->presentCount()});
    in_.release();
    features_meter_.note(warm_up_.warm());
  }
  runner_.close();
}

void ProcessingStage::trackingLoop() {
  FrameTag tag;
  for (;;) {
    PoseSlot& out = out_.slot();
    if (!runner_.finish(out.estimate, tag)) break;
    handOver(out, tag);
  }
}

void ProcessingStage::handOver(PoseSlot& out, const FrameTag& tag) {
  out.trigger_mono_ns = tag.trigger_mono_ns;
  out.cameras_present = tag.cameras_present;
  if (out_.publish()) pose_drops_.fetch_add(1, std::memory_order_relaxed);
  tracking_.store(static_cast<uint8_t>(out.estimate.state), std::memory_order_relaxed);
  unscaled_.store(out.estimate.valid && !out.estimate.metric, std::memory_order_relaxed);
  roughly_metric_.store(out.estimate.valid && out.estimate.roughly_metric, std::memory_order_relaxed);
  afterFrame();
  const uint64_t done = processed_.fetch_add(1, std::memory_order_release) + 1;
  pressure_.done();
  if (!warm_up_.warm() && done >= warmup_frames_) warm_up_.end(done);
  processing_meter_.note(warm_up_.warm());
  background_meter_.note(warm_up_.warm(), processor_.backgroundThreadAllocations());
}

void ProcessingStage::afterFrame() {
  PlaceCounters c;
  if (processor_.placeCounters(c)) {
    relocalizations_.store(c.relocalizations, std::memory_order_relaxed);
    loop_closures_.store(c.loop_closures, std::memory_order_relaxed);
    map_merges_.store(c.map_merges, std::memory_order_relaxed);
    localization_corrections_.store(c.localization_corrections, std::memory_order_relaxed);
    place_keyframes_.store(c.keyframes, std::memory_order_relaxed);
    world_revision_.store(c.world_revision, std::memory_order_relaxed);
  }
  recordStageTimes();
  if (map_saver_) map_saver_->afterFrame(processor_, monotonicNowNs());
}

void ProcessingStage::recordStageTimes() {
  const PipelineTiming* t = processor_.lastTiming();
  if (!t) return;
  const auto ns = [](double ms) { return static_cast<int64_t>(ms * 1e6); };
  stage_times_.front_end.record(ns(t->features_ms));
  stage_times_.odometry.record(ns(t->tracking_ms + t->optimization_ms));
  stage_times_.place_memory.record(ns(t->places_ms));
}

PlaceCounters ProcessingStage::placeCounters() const {
  PlaceCounters c;
  c.relocalizations = relocalizations_.load(std::memory_order_relaxed);
  c.loop_closures = loop_closures_.load(std::memory_order_relaxed);
  c.map_merges = map_merges_.load(std::memory_order_relaxed);
  c.localization_corrections = localization_corrections_.load(std::memory_order_relaxed);
  c.keyframes = place_keyframes_.load(std::memory_order_relaxed);
  c.world_revision = world_revision_.load(std::memory_order_relaxed);
  return c;
}

}  // namespace mcslam::platform
