#pragma once
// The daemon's assembly thread: takes the camera images from the cameras' rings, groups them into rig frames
// (RigAssembler) and queues those for processing. Never waits for the processing: when the rig ring is full, the
// oldest rig frame waiting in it is dropped (counted).
#include <atomic>
#include <thread>
#include <vector>

#include "daemon/frames.hpp"
#include "daemon/rig_assembler.hpp"
#include "realtime/alloc_meter.hpp"
#include "realtime/warm_up.hpp"
#include "sources/camera_rings.hpp"

namespace mcslam::platform {

struct AssemblySettings {
  uint32_t pending_rig_frames = 4;
  RigAssembler::MatchBy match_by = RigAssembler::MatchBy::TriggerCount;
  int64_t tolerance_ns = 0, timeout_ns = 0;
  int priority = 0;  // SCHED_FIFO, 0 = normal scheduling
};

class AssemblyStage {
 public:
  AssemblyStage(const std::vector<std::pair<int, int>>& sizes, const AssemblySettings& settings, CameraRings& in,
                RigRing& out, const WarmUp& warm_up);
  ~AssemblyStage() { stop(); }
  void start();
  // Ends the thread after it has sent on what was captured (incomplete rig frames go out partial).
  void stop();

  uint64_t rigFrames() const { return rig_frames_.load(std::memory_order_relaxed); }
  uint64_t rigDrops() const { return rig_drops_.load(std::memory_order_relaxed); }
  const RigAssembler& assembler() const { return assembler_; }
  uint64_t allocationsSinceWarmup() const { return meter_.since(); }

 private:
  void run();
  bool emit(int64_t now, bool force);

  AssemblySettings settings_;
  CameraRings& in_;
  RigRing& out_;
  const WarmUp& warm_up_;
  RigAssembler assembler_;
  std::atomic<bool> stop_{false};
  std::atomic<uint64_t> rig_frames_{0}, rig_drops_{0};
  ThreadAllocMeter meter_;
  std::thread thread_;
};

}  // namespace mcslam::platform
