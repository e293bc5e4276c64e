#pragma once
// Per-camera ORB extraction on persistent worker threads, one rig frame at a time.
//
// One thread per camera, or a pool of hardware_concurrency() threads when there are more cameras than
// cores (threads take the next camera from a shared counter). One OrbExtractor per thread, sized for the
// largest camera: an extractor's buffers are scratch, so a camera's output does not depend on which
// extractor ran it, and five cameras on two threads keep two extractors' buffers, not five.
// extract() is the per-rig-frame barrier: it returns when every camera is done. The threads start in
// the constructor and stop in the destructor; a frame allocates nothing. A camera's output depends
// only on its image, never on which thread ran it.
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "mcslam/features/orb_extractor.hpp"

namespace mcslam {

struct ImageSize {
  int width = 0, height = 0;
};

class FeatureWorkers {
 public:
  // max_sizes: the largest image of each camera. threads <= 0: min(cameras, hardware_concurrency()).
  // Throws mcslam::InputError on bad options or no camera.
  FeatureWorkers(const OrbOptions& options, const std::vector<ImageSize>& max_sizes, int threads = 0);
  ~FeatureWorkers();
  FeatureWorkers(const FeatureWorkers&) = delete;
  FeatureWorkers& operator=(const FeatureWorkers&) = delete;

  // images, present and out have one entry per camera; out[c] needs capacity >= max_features.
  // An absent camera gets zero features. status (optional, one per camera) receives each result.
  void extract(const ImageView* images, const bool* present, FeatureSet* out, OrbStatus* status = nullptr);

  int cameras() const { return static_cast<int>(max_sizes_.size()); }
  int threads() const { return static_cast<int>(threads_.size()); }
  // The extractor of worker thread `thread` (sized for the largest camera).
  const OrbExtractor& extractor(int thread) const { return extractors_[static_cast<size_t>(thread)]; }

 private:
  void run(int thread);
  void processCamera(int camera, OrbExtractor& extractor);

  std::vector<ImageSize> max_sizes_;     // per camera: an image larger than this is refused
  std::vector<OrbExtractor> extractors_;  // per thread
  std::vector<std::thread> threads_;

  std::mutex mutex_;
  std::condition_variable work_ready_, work_done_;
  uint64_t frame_ = 0;     // incremented for each rig frame (guarded by mutex_)
  int next_camera_ = 0;    // next camera to take (guarded by mutex_)
  int remaining_ = 0;      // cameras not finished yet (guarded by mutex_)
  bool stopping_ = false;  // guarded by mutex_

  // The current frame's arguments, valid while remaining_ > 0.
  const ImageView* images_ = nullptr;
  const bool* present_ = nullptr;
  FeatureSet* out_ = nullptr;
  OrbStatus* status_ = nullptr;
};

}  // namespace mcslam
