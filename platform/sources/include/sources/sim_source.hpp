#pragma once
// Renders the simulator's rig live (mcslam_sim) into the camera rings: no dataset on disk, exact ground
// truth available (simulation()). Simulation frame n is taken at its stamp (n / rate_hz after the start);
// the source renders every camera of a frame, then publishes them together, so rendering slower than
// the assembly timeout never makes partial rig frames.
//   pace fastest:   lossless, the next frame is rendered as soon as the pipeline has taken the previous;
//   pace realtime:  frame n is due n / rate_hz after the start; when rendering falls behind, the source
//                   renders the newest due frame and counts the ones it skipped;
//   trigger.mode software: one frame per trigger, frame n for trigger n (newest trigger first, like a
//                   busy camera), so set rate_hz to trigger.rate_hz for motion in real time.
// `frames` bounds the sequence; at_end exit/loop/idle as for a dataset (looped capture stamps keep growing).
// The renderer's own worker threads are not the daemon's: their allocations are not counted.
#include <atomic>
#include <memory>
#include <thread>
#include <vector>

#include "mcslam/sim/simulation.hpp"
#include "realtime/alloc_meter.hpp"
#include "realtime/doorbell.hpp"
#include "sources/frame_source.hpp"
#include "sources/source_config.hpp"

namespace mcslam::platform {

class SimSource final : public FrameSource, private TriggerOutput {
 public:
  // Builds the world, trajectory and renderer. Throws InputError naming source.sim.
  SimSource(const SimSourceConfig& config, const SourceContext& context);
  ~SimSource() override { stop(); }

  void start(const SourceLinks& links) override;
  void stop() override;
  TriggerOutput* softwareTrigger() override { return software_ ? this : nullptr; }
  bool finished() const override { return finished_.load(std::memory_order_acquire); }
  void health(char* out, std::size_t size) const override;
  uint64_t allocationsSinceWarmup() const override { return meter_.since(); }
  const sim::Simulation& simulation() const { return *sim_; }
  uint64_t emitted() const { return emitted_.load(std::memory_order_relaxed); }
  uint64_t skipped() const { return skipped_.load(std::memory_order_relaxed); }

 private:
  bool fire(uint64_t index) override;
  void run();
  // The next frame number to render (>= next), or false when stopping.
  bool waitTurn(uint64_t next, int64_t start_mono, uint64_t& frame);
  void emit(uint64_t frame, int64_t trigger_mono);

  SimSourceConfig cfg_;
  bool software_;
  std::unique_ptr<sim::Simulation> sim_;
  std::vector<int> sim_cameras_;  // daemon camera -> simulation camera
  uint64_t frames_ = 0;           // frames per pass
  int64_t loop_period_ns_ = 0;    // added to the capture stamps on each pass
  SourceLinks links_;
  CameraRings* rings_ = nullptr;  // links_.rings
  std::atomic<uint64_t> triggered_{0};
  Doorbell trigger_bell_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> finished_{false};
  std::atomic<uint64_t> emitted_{0}, skipped_{0};
  ThreadAllocMeter meter_;
  std::thread thread_;
};

}  // namespace mcslam::platform
