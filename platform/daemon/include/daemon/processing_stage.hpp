#pragma once
// The daemon's processing: rig frames from the rig ring through the FrameProcessor (the SLAM pipeline), poses
// into the pose ring. It runs the processor with the pipeline's StageRunner: a processor with stages on two
// threads, the front-end of the next rig frame (features thread) while the current one is tracked (processing
// thread); one without on the processing thread alone. Reports each processed frame to the back-pressure of a
// lossless replay, and ends the warm-up after so many frames.
#include <atomic>
#include <thread>
#include <vector>

#include "daemon/frames.hpp"
#include "daemon/map_saver.hpp"
#include "mcslam/pipeline/stage_runner.hpp"
#include "realtime/alloc_meter.hpp"
#include "realtime/latency_histogram.hpp"
#include "realtime/warm_up.hpp"
#include "sources/back_pressure.hpp"

namespace mcslam::platform {

// Each processed frame's time in the pipeline's stages (FrameProcessor::lastTiming); any thread may read them.
struct StageTimes {
  LatencyHistogram front_end;     // features: ORB and multi-view
  LatencyHistogram odometry;      // tracking, mapping and the wait for the window solve
  LatencyHistogram place_memory;  // its share of the processing thread
};

class ProcessingStage {
 public:
  // `map_saver` (may be null) saves the processor's map between frames.
  ProcessingStage(FrameProcessor& processor, int cameras, int priority, uint64_t warmup_frames, RigRing& in,
                  PoseRing& out, BackPressure& pressure, WarmUp& warm_up, MapSaver* map_saver = nullptr);
  void start();
  // Asks the threads to end once the rig ring is empty and every prepared frame is finished.
  void requestStop();
  // Every thread it started has left the processor (and its stage runner) for good.
  bool finished() const {
    return done_.load(std::memory_order_acquire) && features_done_.load(std::memory_order_acquire);
  }
  // Polls finished() until it holds or the monotonic clock passes `deadline_ns`; returns finished().
  bool waitFinished(int64_t deadline_ns) const;
  // After requestStop(): join() when finished(), else detach() (a thread stuck inside the processor is left behind).
  void join();
  void detach();
  // detach() left a thread behind: whoever owns what it uses must wait for finished() before releasing it.
  bool leftBehind() const { return left_behind_; }

  uint64_t processed() const { return processed_.load(std::memory_order_relaxed); }
  uint64_t poseDrops() const { return pose_drops_.load(std::memory_order_relaxed); }
  // Frames taken from the rig ring and not yet processed (being prepared, waiting, being finished).
  uint64_t inFlight() const {
    return taken_.load(std::memory_order_relaxed) - processed_.load(std::memory_order_relaxed);
  }
  TrackingState tracking() const { return static_cast<TrackingState>(tracking_.load(std::memory_order_relaxed)); }
  bool unscaled() const { return unscaled_.load(std::memory_order_relaxed); }
  bool roughlyMetric() const { return roughly_metric_.load(std::memory_order_relaxed); }
  // By the features and processing threads and the processor's own (back-end, loop correction).
  uint64_t allocationsSinceWarmup() const {
    return features_meter_.since() + processing_meter_.since() + background_meter_.since();
  }
  // As of the last frame processed (zeros for a processor without place memory).
  PlaceCounters placeCounters() const;
  const StageTimes& stageTimes() const { return stage_times_; }

 private:
  // What the daemon needs to know again about a frame once it is processed.
  struct FrameTag {
    int64_t trigger_mono_ns = 0;
    int cameras_present = 0;
  };
  void setUpThread(const char* name, const char* role);
  void featuresLoop();  // prepare(), on its own thread
  void trackingLoop();  // finish(), on the processing thread
  void wholeLoop();     // both in turn on the processing thread, for a processor without stages
  RigFrameView viewOf(const RigFrame& f);
  void handOver(PoseSlot& out, const FrameTag& tag);

  void afterFrame();  // place counters, stage times, map saving
  void recordStageTimes();

  FrameProcessor& processor_;
  MapSaver* map_saver_;
  StageRunner<FrameTag> runner_;
  int priority_;
  uint64_t warmup_frames_;
  RigRing& in_;
  PoseRing& out_;
  BackPressure& pressure_;
  WarmUp& warm_up_;
  std::vector<ImageView> views_;  // onto the images of the rig frame being prepared
  std::thread features_thread_, processing_thread_;
  std::atomic<bool> stop_{false}, done_{false};
  std::atomic<bool> features_done_{true};  // false while a features thread runs
  bool left_behind_ = false;
  std::atomic<uint64_t> taken_{0}, processed_{0}, pose_drops_{0};
  std::atomic<uint8_t> tracking_{0};
  std::atomic<bool> unscaled_{false};
  std::atomic<bool> roughly_metric_{false};
  std::atomic<uint64_t> relocalizations_{0}, loop_closures_{0}, map_merges_{0}, localization_corrections_{0};
  std::atomic<int64_t> place_keyframes_{0};
  std::atomic<uint16_t> world_revision_{0};
  ThreadAllocMeter features_meter_, processing_meter_;
  ThreadAllocMeter background_meter_;  // the processor's own threads, read after each frame
  StageTimes stage_times_;
};

}  // namespace mcslam::platform
