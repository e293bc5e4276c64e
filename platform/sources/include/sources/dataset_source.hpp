#pragma once
// Replays a recorded dataset (mcslam::Dataset: ASL, EuRoC, KITTI) into the camera rings: at its recorded
// rate (scaled by `speed`), as fast as the pipeline takes frames (lossless), or one frame per software
// trigger. Optionally loops (capture times keep growing across loops so the trajectory stays ordered).
// With `preload` every image is decoded at start and the replay allocates nothing; without it each
// frame is decoded from disk (PNG decoding allocates).
#include <atomic>
#include <memory>
#include <thread>
#include <vector>

#include "mcslam/dataset/dataset.hpp"
#include "realtime/alloc_meter.hpp"
#include "realtime/doorbell.hpp"
#include "sources/frame_source.hpp"
#include "sources/source_config.hpp"

namespace mcslam::platform {

class DatasetSource final : public FrameSource, private TriggerOutput {
 public:
  // Opens the dataset (and preloads it). Throws InputError naming source.dataset.
  DatasetSource(const DatasetSourceConfig& config, const SourceContext& context);
  ~DatasetSource() override { stop(); }

  void start(const SourceLinks& links) override;
  void stop() override;
  TriggerOutput* softwareTrigger() override { return software_ ? this : nullptr; }
  bool finished() const override { return finished_.load(std::memory_order_acquire); }
  uint64_t allocationsSinceWarmup() const override { return meter_.since(); }
  std::size_t frameCount() const { return dataset_.size(); }
  uint64_t emitted() const { return emitted_.load(std::memory_order_relaxed); }

 private:
  bool fire(uint64_t index) override;
  void run();
  bool waitTurn(std::size_t i, uint64_t loop, int64_t start_mono, uint64_t& trigger_index);
  void emit(std::size_t i, uint64_t loop, uint64_t trigger_index, int64_t trigger_mono);

  DatasetSourceConfig cfg_;
  bool software_;
  Dataset dataset_;
  int64_t loop_period_ns_ = 0;  // added to capture times on each loop
  // Preloaded images [frame][camera], or the decode scratch (one frame).
  std::vector<std::vector<Image>> images_;
  std::vector<std::vector<bool>> present_;
  std::string load_error_;
  SourceLinks links_;
  CameraRings* rings_ = nullptr;        // links_.rings
  std::atomic<uint64_t> triggered_{0};  // software triggers received
  Doorbell trigger_bell_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> finished_{false};
  std::atomic<uint64_t> emitted_{0};
  ThreadAllocMeter meter_;
  std::thread thread_;
};

}  // namespace mcslam::platform
