#pragma once
// The daemon's publishing thread: each pose from the pose ring to shared memory, UDP and (when valid) the
// trajectory file, and its trigger-to-publish latency into the histogram. Owns those outputs.
#include <atomic>
#include <memory>
#include <string>
#include <thread>

#include "daemon/daemon_config.hpp"
#include "daemon/frames.hpp"
#include "daemon/trajectory_writer.hpp"
#include "realtime/alloc_meter.hpp"
#include "realtime/latency_histogram.hpp"
#include "realtime/warm_up.hpp"
#include "shm/pose_shm_writer.hpp"
#include "udp/udp_pose_sender.hpp"

namespace mcslam::platform {

class PublishingStage {
 public:
  // Creates the shared-memory segment, the UDP socket and the trajectory file (an existing one is kept as
  // "<path>.previous"). Throws InputError naming the config key.
  PublishingStage(const DaemonConfig& config, PoseRing& in, const WarmUp& warm_up);
  ~PublishingStage() { stop(); }
  void start();
  // Ends the thread after it has published what is in the ring; then syncs the trajectory file and marks the
  // shared-memory segment stopped. Nothing when not started.
  void stop();

  std::string trajectoryPath() const { return trajectory_->path(); }
  uint64_t published() const { return published_.load(std::memory_order_relaxed); }
  const UdpPoseSender& udp() const { return udp_; }
  const TrajectoryWriter& trajectory() const { return *trajectory_; }
  const LatencyHistogram& latency() const { return latency_; }
  uint64_t allocationsSinceWarmup() const { return meter_.since(); }
  // Segments made anew because someone truncated the previous one.
  uint64_t shmReplacements() const { return shm_replacements_.load(std::memory_order_relaxed); }

 private:
  void run();
  void publish(const PoseSlot& slot);
  void replaceLostShm();

  PoseRing& in_;
  const WarmUp& warm_up_;
  UdpPoseSender udp_;
  PublishConfig shm_config_;
  std::unique_ptr<PoseShmWriter> shm_;
  std::atomic<uint64_t> shm_replacements_{0};
  std::unique_ptr<TrajectoryWriter> trajectory_;
  LatencyHistogram latency_;
  std::atomic<bool> stop_{false};
  std::atomic<uint64_t> published_{0};
  uint64_t sequence_ = 0;  // this thread's
  ThreadAllocMeter meter_;
  std::thread thread_;
};

// An output file's path: `name` in output.directory, else in $STATE_DIRECTORY, else in ".".
std::string outputPathFor(const DaemonConfig& config, const std::string& name);
inline std::string trajectoryPathFor(const DaemonConfig& config) {
  return outputPathFor(config, config.output.trajectory);
}

}  // namespace mcslam::platform
