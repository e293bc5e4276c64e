#pragma once
// mcslamd's machinery: trigger -> acquisition (source) -> per-camera rings -> rig assembly -> rig ring
// -> processing (FrameProcessor) -> pose ring -> publishing (shared memory, UDP, trajectory file).
// A processor with stages (the SLAM pipeline) is run on two threads: the front-end of the next rig frame
// while the current one is tracked.
//
// Everything (devices, rings, segment, files) is opened and sized in the constructor, which throws
// InputError naming the config key before any thread starts. After warm-up no thread allocates.
// The trigger and the acquisition never wait for the pipeline: when processing falls behind, the
// oldest complete rig frame waiting for it is dropped and counted.
#include <atomic>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "daemon/daemon_config.hpp"
#include "daemon/frames.hpp"
#include "daemon/rig_assembler.hpp"
#include "daemon/trajectory_writer.hpp"
#include "gpio/trigger_line.hpp"
#include "realtime/alloc_meter.hpp"
#include "realtime/doorbell.hpp"
#include "realtime/drop_oldest_ring.hpp"
#include "realtime/latency_histogram.hpp"
#include "shm/pose_shm_writer.hpp"
#include "sources/frame_source.hpp"
#include "trigger/trigger_thread.hpp"
#include "udp/udp_pose_sender.hpp"

namespace mcslam::platform {

struct DaemonStats {
  uint64_t triggers = 0, trigger_failures = 0, triggers_missed = 0;
  uint64_t camera_frames = 0, camera_drops = 0, bad_frames = 0, lost_events = 0;
  uint64_t rig_frames = 0, partial_frames = 0, late_images = 0, rig_drops = 0;
  uint64_t processed = 0, published = 0, pose_drops = 0;
  uint64_t udp_sent = 0, udp_failed = 0, trajectory_poses = 0, trajectory_errors = 0;
  TrackingState tracking = TrackingState::NotInitialized;
  bool unscaled = false;  // the last pose's position is not in metres (PoseEstimate::metric)
  uint64_t latency_count = 0;
  int64_t latency_p50_ns = 0, latency_p99_ns = 0;  // trigger -> published
  bool warm = false;
  uint64_t frames_after_warmup = 0, allocations_after_warmup = 0;  // our threads
  bool source_finished = false;
};

class Daemon {
 public:
  // `source` may be given (tests); otherwise it is created from the config.
  Daemon(const DaemonConfig& config, std::unique_ptr<FrameProcessor> processor,
         std::unique_ptr<FrameSource> source = nullptr);
  ~Daemon();
  Daemon(const Daemon&) = delete;
  Daemon& operator=(const Daemon&) = delete;

  void start();
  // Stops in order (trigger, source, assembly, processing, publishing), then fsyncs the trajectory and
  // writes the pipeline's refined extrinsics (output.extrinsics, fsynced).
  // Returns false when the processing thread did not finish within `processing_grace_ns` (it is then
  // left behind, and no extrinsics are written; the trajectory of what was published is still
  // complete and synced).
  bool stop(int64_t processing_grace_ns = 1500000000);

  DaemonStats stats() const;
  // The source has ended and every frame it delivered has been processed and published.
  bool drained() const;
  void health(char* out, std::size_t size) const { source_->health(out, size); }
  const DaemonConfig& config() const { return config_; }
  std::string trajectoryPath() const { return trajectory_->path(); }
  // Empty when output.extrinsics is empty (not written).
  const std::string& extrinsicsPath() const { return extrinsics_path_; }
  bool extrinsicsWritten() const { return extrinsics_written_; }

 private:
  void assemblyLoop();
  void processingLoop();
  void wholeFrameLoop();  // processing for a processor without stages: process() per rig frame
  void featuresLoop();    // stage one (prepare) on its own thread, when the processor has stages
  void trackingLoop();    // stage two (finish) on the processing thread
  void handOver(PoseSlot& out);  // a processed frame's pose to the publisher, warm-up bookkeeping
  RigFrame* nextRigFrame();      // waits for the next rig frame; null once stopping and the ring is empty
  RigFrameView viewOf(const RigFrame& f);  // views_ onto its images
  void publishingLoop();
  bool emitRigFrame(int64_t now, bool force);
  void publishPose(const PoseSlot& slot);
  void writeRefinedExtrinsics();

  DaemonConfig config_;
  std::unique_ptr<FrameProcessor> processor_;
  std::atomic<uint64_t> processed_{0};
  std::unique_ptr<FrameSource> source_;
  std::vector<std::pair<int, int>> sizes_;

  CameraRings camera_rings_;
  RigAssembler assembler_;
  DropOldestRing<RigFrame> rig_ring_;
  Doorbell rig_bell_;
  DropOldestRing<PoseSlot> pose_ring_;
  Doorbell pose_bell_;
  std::vector<ImageView> views_;

  std::unique_ptr<PoseShmWriter> shm_;
  UdpPoseSender udp_;
  std::unique_ptr<TrajectoryWriter> trajectory_;  // opened last: a failed start-up leaves files alone
  std::string extrinsics_path_;
  bool extrinsics_written_ = false;

  TriggerLog trigger_log_;
  std::unique_ptr<TriggerLine> gpio_line_;
  std::unique_ptr<PulseTrigger> pulse_;
  std::unique_ptr<TriggerThread> trigger_thread_;

  // Frames between the two processing stages: the processor holds them in its slots, used in order;
  // staged_head_ counts the prepared ones, staged_tail_ the finished ones.
  struct StagedFrame {
    int64_t trigger_mono_ns = 0;
    int cameras_present = 0;
  };
  std::vector<StagedFrame> staged_;
  std::atomic<uint64_t> staged_head_{0}, staged_tail_{0};
  std::atomic<bool> features_done_{false};
  Doorbell staged_bell_, stage_free_bell_;

  std::thread assembly_thread_, features_thread_, processing_thread_, publishing_thread_;
  std::atomic<bool> stop_assembly_{false}, stop_processing_{false}, stop_publishing_{false};
  std::atomic<bool> processing_done_{false};
  bool started_ = false, stopped_ = false;

  std::atomic<uint64_t> rig_frames_{0}, rig_drops_{0}, published_{0}, pose_drops_{0};
  std::atomic<uint8_t> tracking_{0};
  std::atomic<bool> unscaled_{false};
  std::atomic<bool> warm_{false};
  std::atomic<uint64_t> processed_at_warmup_{0};
  LatencyHistogram latency_;
  ThreadAllocMeter assembly_meter_, features_meter_, processing_meter_, publishing_meter_;
  uint64_t sequence_ = 0;  // publisher only
};

// An output file's path: `name` in output.directory, else in $STATE_DIRECTORY, else in ".".
std::string outputPathFor(const DaemonConfig& config, const std::string& name);
inline std::string trajectoryPathFor(const DaemonConfig& config) {
  return outputPathFor(config, config.output.trajectory);
}

}  // namespace mcslam::platform
