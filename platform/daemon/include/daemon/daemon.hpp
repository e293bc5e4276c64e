#pragma once
// mcslamd's machinery, as stages with typed rings between them (docs/design/stages.md):
//   trigger (TriggerStage) -> source (FrameSource, its own threads) -> CameraRings -> assembly (AssemblyStage)
//   -> RigRing -> processing (ProcessingStage: the pipeline's StageRunner on one or two threads) -> PoseRing
//   -> publishing (PublishingStage: shared memory, UDP, trajectory file).
// The Daemon owns the stages and the rings, wires them, starts and stops them in order and gathers their counters.
//
// Everything (devices, rings, segment, files) is opened and sized in the constructor, which throws
// InputError naming the config key before any thread starts. After warm-up no thread allocates.
// The trigger and the acquisition never wait for the pipeline: when processing falls behind, the
// oldest complete rig frame waiting for it is dropped and counted. Only a lossless replay (rate or pace
// fastest) waits for the pipeline, through the BackPressure that the processing reports to.
#include <memory>
#include <string>
#include <vector>

#include "daemon/assembly_stage.hpp"
#include "daemon/daemon_config.hpp"
#include "daemon/frames.hpp"
#include "daemon/map_saver.hpp"
#include "daemon/processing_stage.hpp"
#include "daemon/publishing_stage.hpp"
#include "daemon/trigger_stage.hpp"
#include "realtime/warm_up.hpp"
#include "sources/back_pressure.hpp"
#include "sources/camera_rings.hpp"
#include "sources/frame_source.hpp"

namespace mcslam::platform {

struct DaemonStats {
  uint64_t triggers = 0, trigger_failures = 0, triggers_missed = 0;
  uint64_t camera_frames = 0, camera_drops = 0, bad_frames = 0, lost_events = 0;
  uint64_t rig_frames = 0, partial_frames = 0, late_images = 0, rig_drops = 0;
  uint64_t processed = 0, published = 0, pose_drops = 0;
  uint64_t udp_sent = 0, udp_failed = 0, trajectory_poses = 0, trajectory_errors = 0, trajectory_reopened = 0;
  uint64_t shm_replacements = 0;            // the pose segment was truncated by another process and made anew
  int trajectory_errno = 0, udp_errno = 0;  // the reasons of the last failed trajectory write and UDP send
  TrackingState tracking = TrackingState::NotInitialized;
  bool unscaled = false;        // the last pose's position is not in metres (PoseEstimate::metric)
  bool roughly_metric = false;  // ... but roughly so (PoseEstimate::roughly_metric)
  uint64_t latency_count = 0;
  int64_t latency_p50_ns = 0, latency_p99_ns = 0;  // trigger -> published
  struct StageTime {
    int64_t p50_ns = 0, p99_ns = 0;
  };
  StageTime front_end_time, odometry_time, place_memory_time;  // per frame (ProcessingStage::stageTimes)
  bool warm = false;
  uint64_t frames_after_warmup = 0, allocations_after_warmup = 0;  // our threads
  bool source_finished = false;
  // Place memory: what the status reports of it, and the map file's saves.
  PlaceCounters places;
  uint64_t map_saves = 0, map_save_failures = 0;
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
  // Stops in order (trigger, source, assembly, processing, publishing), then fsyncs the trajectory,
  // writes the pipeline's refined extrinsics (output.extrinsics, fsynced) and saves the map (map.save).
  // Returns false when the processing did not finish within `processing_grace_ns` (its threads are then
  // left behind, and no extrinsics are written; the trajectory of what was published is still
  // complete and synced).
  bool stop(int64_t processing_grace_ns = 1500000000);

  DaemonStats stats() const;
  // The source has ended and every frame it delivered has been processed and published.
  bool drained() const;
  void health(char* out, std::size_t size) const { source_->health(out, size); }
  const DaemonConfig& config() const { return config_; }
  std::string trajectoryPath() const { return publishing_.trajectoryPath(); }
  // Empty when output.extrinsics is empty (not written).
  const std::string& extrinsicsPath() const { return extrinsics_path_; }
  bool extrinsicsWritten() const { return extrinsics_written_; }

 private:
  void writeRefinedExtrinsics();
  // map.load into the processor (a missing file: a first start; an unreadable one: InputError, or set aside with
  // map.on_unreadable start_empty), and the saver of map.save.
  static std::unique_ptr<MapSaver> prepareMap(const DaemonConfig& config, FrameProcessor& processor);

  DaemonConfig config_;
  std::unique_ptr<FrameProcessor> processor_;
  std::unique_ptr<FrameSource> source_;
  std::vector<std::pair<int, int>> sizes_;
  std::unique_ptr<MapSaver> map_saver_;  // before the stages: a map that cannot be loaded ends start-up first

  // The rings and signals between the stages; the stages hold references to them.
  CameraRings camera_rings_;
  RigRing rig_ring_;
  PoseRing pose_ring_;
  BackPressure pressure_;
  WarmUp warm_up_;

  TriggerStage trigger_;
  AssemblyStage assembly_;
  ProcessingStage processing_;
  PublishingStage publishing_;  // opens the files: last, so a failed start-up leaves them alone
  std::string extrinsics_path_;
  bool extrinsics_written_ = false;
  bool started_ = false, stopped_ = false;
};

}  // namespace mcslam::platform
