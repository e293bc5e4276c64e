#include "daemon/processing_stage.hpp"

#include <spdlog/spdlog.h>

#include "realtime/scheduling.hpp"

namespace mcslam::platform {

ProcessingStage::ProcessingStage(FrameProcessor& processor, int cameras, int priority, uint64_t warmup_frames,
                                 RigRing& in, PoseRing& out, BackPressure& pressure, WarmUp& warm_up)
    : runner_(processor),
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
    features_thread_ = std::thread([this] {
      setUpThread("mcslam-features", "features");
      featuresLoop();
    });
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

void ProcessingStage::detach() {
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
  const uint64_t done = processed_.fetch_add(1, std::memory_order_release) + 1;
  pressure_.done();
  if (!warm_up_.warm() && done >= warmup_frames_) warm_up_.end(done);
  processing_meter_.note(warm_up_.warm());
}

}  // namespace mcslam::platform
